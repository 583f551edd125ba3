# SPDX-License-Identifier: LGPL-2.1-or-later
"""libgstpfap from Python (GstPfap-1.0 through PyGObject), as an application uses it.

meson runs these against the build tree (tests/python/meson.build): GI_TYPELIB_PATH and
LD_LIBRARY_PATH find the library and its typelib, GST_PLUGIN_PATH the plugins, and
PFAP_FAP_STATE_VALUES the C++ program that gives libpfap's own FAP state values.
"""
import os
import random
import re
import subprocess

import gi

gi.require_version("Gst", "1.0")
gi.require_version("GstApp", "1.0")
gi.require_version("GstPfap", "1.0")
from gi.repository import GLib, Gst, GstApp, GstPfap  # noqa: E402

import pytest  # noqa: E402

Gst.init(None)

SEEDS = [1, 2, 3]
PHONEME_FLAGS = (GstPfap.EventFlags.STRESS | GstPfap.EventFlags.WORD_BEGIN)


def random_fap(rng):
    """Any valid FAP, the extremes of every field included."""
    if rng.random() < 0.1:
        amplitude = rng.choice([GstPfap.MAX_AMPLITUDE, -GstPfap.MAX_AMPLITUDE])
    else:
        amplitude = rng.randint(-GstPfap.MAX_AMPLITUDE, GstPfap.MAX_AMPLITUDE)
    transition = (GstPfap.MAX_TRANSITION_MS if rng.random() < 0.1
                  else rng.randint(0, GstPfap.MAX_TRANSITION_MS))
    return GstPfap.Fap.new(rng.randint(GstPfap.MIN_FAP_INDEX, GstPfap.MAX_FAP_INDEX),
                           amplitude, transition, GstPfap.Curve(rng.randint(1, 3)))


def random_session(seed, n_phonemes):
    """Seeded phonemes as a TTS engine gives them (tests/gst/test_pipeline.cc does the same in
    C++): contiguous, 0..5 FAPs each, sentences ended by end of text and begun with a sentence
    start after a pause. Returns (pts, event, fields): fields are the values the event was
    given, as event_fields() reads them back, so that a setter or getter that lost a value
    cannot go unnoticed."""
    rng = random.Random(seed)
    t = Gst.SECOND + rng.randint(0, 999_999_999)
    sentence_start = True
    session = []
    for i in range(n_phonemes):
        event = GstPfap.Event.new(GstPfap.EventKind.PHONEME)
        symbol = rng.randint(0, 255)
        duration = GstPfap.MAX_DURATION_MS if rng.random() < 0.05 else rng.randint(0, 400)
        f0 = rng.randint(0, 255)
        event.set_symbol(symbol)
        event.set_duration_ms(duration)
        event.set_f0(f0)
        flags = GstPfap.EventFlags(0)
        if rng.random() < 0.3:
            flags |= GstPfap.EventFlags.STRESS
        if rng.random() < 0.3:
            flags |= GstPfap.EventFlags.WORD_BEGIN
        end_of_text = i + 1 == n_phonemes or rng.random() < 0.06
        if end_of_text:
            flags |= GstPfap.EventFlags.END_OF_TEXT
        if sentence_start:
            flags |= GstPfap.EventFlags.SENTENCE_START
        event.set_flags(flags)
        faps = [random_fap(rng) for _ in range(rng.randint(0, 5))]
        for fap in faps:
            event.add_fap(fap)
        fields = (GstPfap.EventKind.PHONEME, symbol, duration, f0, int(flags),
                  [fap_tuple(f) for f in faps])
        session.append((t, event, fields))
        t += duration * Gst.MSECOND
        sentence_start = end_of_text
        if end_of_text:
            t += rng.randint(1, 1500) * Gst.MSECOND + rng.randint(0, 999_999)
    return session


def fap_tuple(fap):
    return (fap.index, fap.amplitude, fap.transition_ms, int(fap.curve))


def event_fields(event):
    return (event.get_kind(), event.get_symbol(), event.get_duration_ms(), event.get_f0(),
            int(event.get_flags()), [fap_tuple(f) for f in event.get_faps()])


def run_pipeline(description, buffers, timeout_s=20):
    """Pushes `buffers` into appsrc `src`, pulls everything from appsink `sink` until EOS."""
    pipeline = Gst.parse_launch(description)
    src = pipeline.get_by_name("src")
    sink = pipeline.get_by_name("sink")
    assert pipeline.set_state(Gst.State.PLAYING) != Gst.StateChangeReturn.FAILURE
    try:
        for buffer in buffers:
            assert src.push_buffer(buffer) == Gst.FlowReturn.OK
        src.end_of_stream()
        out = []
        while True:
            sample = sink.try_pull_sample(timeout_s * Gst.SECOND)
            if sample is None:
                break
            out.append(sample.get_buffer())
        assert sink.is_eos(), "no EOS within %d s" % timeout_s
        bus = pipeline.get_bus()
        error = bus.pop_filtered(Gst.MessageType.ERROR)
        assert error is None, error.parse_error()
        return out
    finally:
        pipeline.set_state(Gst.State.NULL)


@pytest.mark.parametrize("seed", SEEDS)
def test_every_field_round_trips_through_pay_and_depay(seed):
    session = random_session(seed, 200)
    buffers = []
    for pts, event, _ in session:
        buffer = event.to_buffer()
        buffer.pts = pts
        buffers.append(buffer)
    got = run_pipeline(
        "appsrc name=src format=time caps=" + GstPfap.CAPS + " ! rtppfappay ! rtppfapdepay ! "
        "appsink name=sink sync=false emit-signals=false wait-on-eos=false", buffers)
    assert len(got) == len(session)
    for i, ((pts, _, fields), buffer) in enumerate(zip(session, got)):
        back = GstPfap.Event.new_from_buffer(buffer)
        assert event_fields(back) == fields, "event %d (seed %d)" % (i, seed)
        assert buffer.pts == pts, "event %d (seed %d)" % (i, seed)
        assert buffer.duration == fields[2] * Gst.MSECOND


@pytest.mark.parametrize("seed", SEEDS)
def test_random_events_of_every_kind_round_trip_through_buffers(seed):
    """What the payloader does not send (state events, the uncertain flag) round-trips
    through buffers: a state event keeps its flags and FAPs, and carries no phoneme."""
    rng = random.Random(seed)
    for i in range(300):
        kind = GstPfap.EventKind(rng.randint(1, 3))
        symbol, duration, f0 = rng.randint(0, 255), rng.randint(0, 4095), rng.randint(0, 255)
        flags = GstPfap.EventFlags(rng.randint(0, 31))
        faps = [random_fap(rng) for _ in range(rng.randint(0, 8))]
        event = GstPfap.Event.new(kind)
        event.set_symbol(symbol)
        event.set_duration_ms(duration)
        event.set_f0(f0)
        event.set_flags(flags)
        for fap in faps:
            event.add_fap(fap)
        phoneme = kind == GstPfap.EventKind.PHONEME
        expected = (kind, symbol if phoneme else 0, duration if phoneme else 0,
                    f0 if phoneme else 0, int(flags), [fap_tuple(f) for f in faps])
        buffer = event.to_buffer()
        assert buffer.duration == (duration * Gst.MSECOND if phoneme else Gst.CLOCK_TIME_NONE)
        assert event_fields(GstPfap.Event.new_from_buffer(buffer)) == expected, \
            "event %d (seed %d)" % (i, seed)


def test_fap_fields_and_state_events_round_trip_through_bytes():
    event = GstPfap.Event.new(GstPfap.EventKind.RECOVERED)
    event.set_flags(GstPfap.EventFlags.UNCERTAIN)
    fap = GstPfap.Fap()
    fap.index, fap.amplitude, fap.transition_ms, fap.curve = 74, -2529600, 16383, \
        GstPfap.Curve.TRIANGLE
    event.add_fap(fap)
    buffer = event.to_buffer()
    assert buffer.duration == Gst.CLOCK_TIME_NONE
    ok, info = buffer.map(Gst.MapFlags.READ)
    assert ok
    data = bytes(info.data)
    buffer.unmap(info)
    # docs/markup.md: kind 2, flags 16, no phoneme, one FAP: 74, curve 2, 16383, -2529600.
    assert data == bytes([2, 16, 0, 0, 0, 0, 0, 1, 74, 2, 0x3F, 0xFF]) + \
        (-2529600).to_bytes(4, "big", signed=True)
    back = GstPfap.Event.new_from_data(data)
    assert event_fields(back) == event_fields(event)
    assert fap_tuple(back.get_fap(0)) == (74, -2529600, 16383, 2)
    assert back.get_fap(1) is None


@pytest.mark.parametrize("data", [b"", b"\x01\x00\x00", b"\x04" + bytes(7),
                                  b"\x01\x00\x00\x00\x00\x00\x00\x01"],
                         ids=["empty", "short-header", "unknown-kind", "missing-fap"])
def test_malformed_bytes_raise_a_malformed_gerror(data):
    with pytest.raises(GLib.Error) as raised:
        # GStreamer wraps no empty memory: an empty buffer is a new one.
        GstPfap.Event.new_from_buffer(Gst.Buffer.new_wrapped(data) if data else Gst.Buffer.new())
    assert raised.value.matches(GstPfap.event_error_quark(), GstPfap.EventError.MALFORMED)
    assert "not a valid application/x-pfap event" in raised.value.message


def test_out_of_range_values_raise_with_the_value_named():
    event = GstPfap.Event.new(GstPfap.EventKind.PHONEME)
    event.add_fap(GstPfap.Fap.new(75, 0, 0, GstPfap.Curve.LINEAR))
    with pytest.raises(GLib.Error) as raised:
        event.to_buffer()
    assert raised.value.matches(GstPfap.event_error_quark(), GstPfap.EventError.OUT_OF_RANGE)
    assert "index 75" in raised.value.message
    # The binding refuses values that do not fit the field's type before C sees them.
    with pytest.raises(OverflowError):
        event.set_duration_ms(70000)


def test_alphabet_maps_symbols_to_names_and_visemes():
    assert GstPfap.Alphabet.find("no-such-alphabet") is None
    arpabet = GstPfap.Alphabet.find(GstPfap.ALPHABET_ARPABET)
    assert arpabet.get_name() == "x-pfap-arpabet"
    assert arpabet.get_n_symbols() == 40
    names = [arpabet.get_phoneme_name(s) for s in range(arpabet.get_n_symbols())]
    assert names[:3] == ["pause", "AA", "AE"] and names[-1] == "ZH"
    assert arpabet.get_phoneme_name(40) is None
    found, symbol = arpabet.lookup_symbol("B")
    assert found and names[symbol] == "B"
    assert arpabet.get_viseme(symbol) == GstPfap.Viseme.PBM
    assert arpabet.lookup_symbol("nope")[0] is False


def test_bookmarks_parse_and_format():
    faps = GstPfap.bookmarks_parse("<FAP 2 1 40 2 30 2000 3> <FAP 48 -7 0 1>",
                                   GstPfap.MAX_BOOKMARKS)
    assert [fap_tuple(f) for f in faps] == [(69, 40, 2000, 3), (70, 30, 2000, 3),
                                            (48, -7, 0, 1)]
    text = GstPfap.bookmarks_format(faps)
    assert text == "<FAP 69 40 2000 3><FAP 70 30 2000 3><FAP 48 -7 0 1>"
    assert [fap_tuple(f) for f in GstPfap.bookmarks_parse(text, 40)] == \
        [fap_tuple(f) for f in faps]


@pytest.mark.parametrize("text, code, position", [
    ("<FAP 48 1 16384 1>", GstPfap.BookmarkError.TRANSITION_OUT_OF_RANGE, 10),
    ("<FAP 75 1 0 1>", GstPfap.BookmarkError.UNKNOWN_FAP, 5),
    ("<FAP 48 1 0 4>", GstPfap.BookmarkError.CURVE_OUT_OF_RANGE, 12),
    ("  <FAP 48 1 0 1", GstPfap.BookmarkError.UNTERMINATED, 2),
    ("<FAP 48 x 0 1>", GstPfap.BookmarkError.BAD_NUMBER, 8),
], ids=["transition", "unknown-fap", "curve", "unterminated", "bad-number"])
def test_bookmark_errors_are_gerrors_with_their_position(text, code, position):
    with pytest.raises(GLib.Error) as raised:
        GstPfap.bookmarks_parse(text, GstPfap.MAX_BOOKMARKS)
    assert raised.value.matches(GstPfap.bookmark_error_quark(), code), raised.value.message
    match = re.match(r"at byte (\d+): ", raised.value.message)
    assert match, raised.value.message
    assert int(match.group(1)) == position


def test_fap_state_amplitudes_equal_libpfaps():
    """Python's FapState and the C++ library's, fed the same random events (every kind and
    curve), give the same amplitudes at the same times, to the last bit."""
    rng = random.Random(7)
    state = GstPfap.FapState.new()
    script, queries = [], []
    t = Gst.SECOND
    for _ in range(300):
        kind = rng.choices(list(GstPfap.EventKind.__enum_values__.values()),
                           weights=[8, 1, 1])[0]
        event = GstPfap.Event.new(kind)
        faps = [random_fap(rng) for _ in range(rng.randint(0, 4))]
        for fap in faps:
            fap.transition_ms = rng.randint(0, 800)  # transitions that end within the run
            event.add_fap(fap)
        state.apply_event(event, t)
        script.append("E %d %d %d %s" % (int(kind), t, len(faps),
                                         " ".join("%d %d %d %d" % fap_tuple(f) for f in faps)))
        for _ in range(5):
            t += rng.randint(0, 60) * Gst.MSECOND + rng.randint(0, 999_999)
            index = rng.randint(GstPfap.MIN_FAP_INDEX, GstPfap.MAX_FAP_INDEX)
            script.append("Q %d %d" % (t, index))
            queries.append(state.get_amplitude(index, t))
            script.append("S %d" % index)
            queries.append(float(state.get_settled(index)))
    cpp = subprocess.run([os.environ["PFAP_FAP_STATE_VALUES"]], input="\n".join(script),
                         capture_output=True, text=True, check=True, timeout=30)
    expected = [float(line) for line in cpp.stdout.split()]
    assert len(expected) == len(queries)
    moving = sum(1 for value in queries if value != round(value))
    assert moving > 50, "too few queries inside a transition to compare curves"
    for i, (got, want) in enumerate(zip(queries, expected)):
        assert got == want, "value %d: Python %r, C++ %r" % (i, got, want)


def test_fap_state_refuses_an_out_of_range_fap_and_keeps_its_state():
    state = GstPfap.FapState.new()
    state.apply_fap(GstPfap.Fap.new(3, 100, 0, GstPfap.Curve.LINEAR), 0)
    with pytest.raises(GLib.Error) as raised:
        state.apply_fap(GstPfap.Fap.new(3, GstPfap.MAX_AMPLITUDE + 1, 0, GstPfap.Curve.LINEAR),
                        Gst.SECOND)
    assert raised.value.matches(GstPfap.event_error_quark(), GstPfap.EventError.OUT_OF_RANGE)
    assert state.get_settled(3) == 100
    assert state.is_at_rest(3, Gst.SECOND)
