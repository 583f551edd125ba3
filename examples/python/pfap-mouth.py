#!/usr/bin/python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""A mouth in the terminal, moved by the FAPs of a PFAP stream.

Events from appsink go into a GstPfap.FapState at their time; a timer asks it the jaw and lip
FAPs at the pipeline's running time, 25 times a second, and draws the mouth: the app drives
its own avatar as pfapface does. From a file, or from RTP on UDP:

    pfap-mouth.py docs/examples/face.pfap
    pfap-mouth.py --port 5004

From a build tree, point GI_TYPELIB_PATH and LD_LIBRARY_PATH at build/gst-libs/gst/pfap (and
build/lib) and GST_PLUGIN_PATH at build/gst (docs/apps.md).
"""
import argparse
import sys

import gi

gi.require_version("Gst", "1.0")
gi.require_version("GstApp", "1.0")
gi.require_version("GstPfap", "1.0")
from gi.repository import GLib, Gst, GstApp, GstPfap  # noqa: E402,F401

# MPEG-4 FAPs (ISO/IEC 14496-2 Annex C) and what a mouth of a few characters can show of them:
# open_jaw, the inner lips' middles, and the corners stretched and raised (a smile).
OPEN_JAW, LOWER_T_MIDLIP, RAISE_B_MIDLIP = 3, 4, 5
STRETCH_L_CORNERLIP, STRETCH_R_CORNERLIP = 6, 7
RAISE_L_CORNERLIP, RAISE_R_CORNERLIP = 12, 13
JOY = 69  # expression 1


def draw(state, time):
    """The mouth at `time` as lines of text."""
    def fap(index):
        return state.get_amplitude(index, time)

    opening = fap(OPEN_JAW) + fap(LOWER_T_MIDLIP) - fap(RAISE_B_MIDLIP)
    rows = max(0, min(4, round(opening / 60)))
    width = 12 + max(-4, min(6, round((fap(STRETCH_L_CORNERLIP) + fap(STRETCH_R_CORNERLIP)) / 60)))
    smile = fap(RAISE_L_CORNERLIP) + fap(RAISE_R_CORNERLIP) + fap(JOY)
    left, right = ("\\", "/") if smile > 40 else ("/", "\\") if smile < -40 else ("-", "-")
    lines = [" " + "_" * width]
    lines += ["|" + " " * width + "|" for _ in range(rows)]
    lines += [left + "_" * width + right]
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("file", nargs="?", help="a .pfap text file (docs/text-format.md)")
    parser.add_argument("--port", type=int, default=5004,
                        help="without a file, receive RTP on this UDP port (default 5004)")
    parser.add_argument("--plain", action="store_true",
                        help="print each frame below the last instead of redrawing in place")
    args = parser.parse_args()

    Gst.init(None)
    if args.file:
        pipeline = Gst.parse_launch("filesrc name=src ! pfaptextparse ! appsink name=sink sync=true")
        pipeline.get_by_name("src").set_property("location", args.file)
    else:
        pipeline = Gst.parse_launch(
            "udpsrc name=src caps=\"application/x-rtp,media=application,encoding-name=PFAP,"
            "clock-rate=44100\" ! rtpjitterbuffer max-dropout-time=0 max-misorder-time=0 "
            "! rtppfapdepay ! appsink name=sink sync=true")
        pipeline.get_by_name("src").set_property("port", args.port)
    sink = pipeline.get_by_name("sink")
    state = GstPfap.FapState.new()
    loop = GLib.MainLoop()
    drawn = [0]

    def on_sample(appsink):
        # sync=true: each event comes when the clock reaches it, so its PTS (in running time,
        # the segment starting at 0) is also when it applies.
        sample = appsink.pull_sample()
        buffer = sample.get_buffer()
        segment = sample.get_segment()
        time = segment.to_running_time(Gst.Format.TIME, buffer.pts)
        try:
            state.apply_event(GstPfap.Event.new_from_buffer(buffer), time)
        except GLib.Error as e:
            print("dropped: %s" % e.message, file=sys.stderr)
        return Gst.FlowReturn.OK

    def on_frame():
        clock = pipeline.get_clock()
        if clock is None:
            return True
        now = clock.get_time() - pipeline.get_base_time()
        lines = draw(state, now)
        if not args.plain and drawn[0]:
            sys.stdout.write("\x1b[%dA\x1b[J" % drawn[0])  # back up over the last frame
        sys.stdout.write("\n".join(lines) + "\n")
        sys.stdout.flush()
        drawn[0] = len(lines)
        return True

    def on_message(bus, message):
        if message.type == Gst.MessageType.EOS:
            GLib.timeout_add(1000, loop.quit)  # the last transitions run on after the events
        elif message.type == Gst.MessageType.ERROR:
            error, _ = message.parse_error()
            print("error: %s" % error.message, file=sys.stderr)
            loop.quit()

    sink.set_property("emit-signals", True)
    sink.connect("new-sample", on_sample)
    bus = pipeline.get_bus()
    bus.add_signal_watch()
    bus.connect("message", on_message)
    GLib.timeout_add(40, on_frame)
    pipeline.set_state(Gst.State.PLAYING)
    try:
        loop.run()
    except KeyboardInterrupt:
        pass
    pipeline.set_state(Gst.State.NULL)
    return 0


if __name__ == "__main__":
    sys.exit(main())
