#!/usr/bin/python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""Prints the phonemes and FAPs of a PFAP RTP stream received on UDP.

    udpsrc ! rtpjitterbuffer max-dropout-time=0 max-misorder-time=0 ! rtppfapdepay ! appsink

(the jitterbuffer's windows fixed, so that a flood of spoofed packets cannot stall it:
docs/security.md, "Floods").
Each application/x-pfap buffer from appsink is read with GstPfap.Event (libgstpfap through
GObject-Introspection), phoneme symbols named with the stream's alphabet. Send it something:

    gst-launch-1.0 filesrc location=docs/examples/hello.pfap ! pfaptextparse alphabet=x-pfap-arpabet ! \\
        rtppfappay ! udpsink host=127.0.0.1 port=5004

It runs until Ctrl-C (or --idle-exit). From a build tree, point GI_TYPELIB_PATH and
LD_LIBRARY_PATH at build/gst-libs/gst/pfap (and build/lib) and GST_PLUGIN_PATH at build/gst
(docs/apps.md).
"""
import argparse
import signal
import sys

import gi

gi.require_version("Gst", "1.0")
gi.require_version("GstApp", "1.0")
gi.require_version("GstPfap", "1.0")
from gi.repository import GLib, Gst, GstApp, GstPfap  # noqa: E402,F401

FLAG_NAMES = [(GstPfap.EventFlags.STRESS, "stress"), (GstPfap.EventFlags.WORD_BEGIN, "word"),
              (GstPfap.EventFlags.END_OF_TEXT, "end-of-text"),
              (GstPfap.EventFlags.SENTENCE_START, "sentence"),
              (GstPfap.EventFlags.UNCERTAIN, "uncertain")]


def describe(event, pts, alphabet):
    kind = event.get_kind()
    time = "%.3f" % (pts / Gst.SECOND) if pts != Gst.CLOCK_TIME_NONE else "-"
    flags = ",".join(name for flag, name in FLAG_NAMES if event.get_flags() & flag)
    if kind == GstPfap.EventKind.PHONEME:
        symbol = event.get_symbol()
        name = alphabet.get_phoneme_name(symbol) if alphabet else None
        line = "%s phoneme %s %d ms f0 %d Hz" % (time, name or "#%d" % symbol,
                                                  event.get_duration_ms(), 2 * event.get_f0())
    elif kind == GstPfap.EventKind.RECOVERED:
        line = "%s recovered" % time
    else:
        line = "%s complete state" % time
    if flags:
        line += " [%s]" % flags
    for fap in event.get_faps():
        line += "\n    FAP %d -> %d over %d ms (%s)" % (
            fap.index, fap.amplitude, fap.transition_ms, fap.curve.value_nick)
    return line


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--port", type=int, default=5004, help="UDP port (default 5004)")
    parser.add_argument("--address", default="127.0.0.1", help="address to listen on")
    parser.add_argument("--clock-rate", type=int, default=44100,
                        help="the stream's RTP clock rate (SDP a=rtpmap PFAP/<rate>)")
    parser.add_argument("--alphabet", default=None,
                        help="phoneme alphabet when the caps name none (default: the caps', "
                             "else " + GstPfap.ALPHABET_ARPABET + ")")
    parser.add_argument("--idle-exit", type=float, default=0,
                        help="exit after this many seconds without an event (0: never)")
    args = parser.parse_args()

    Gst.init(None)
    pipeline = Gst.parse_launch(
        "udpsrc name=src ! rtpjitterbuffer max-dropout-time=0 max-misorder-time=0 "
        "! rtppfapdepay ! "
        "appsink name=sink caps=%s sync=false emit-signals=true" % GstPfap.CAPS)
    src = pipeline.get_by_name("src")
    src.set_property("address", args.address)
    src.set_property("port", args.port)
    src.set_property("caps", Gst.Caps.from_string(
        "application/x-rtp,media=application,encoding-name=PFAP,clock-rate=%d" % args.clock_rate))
    sink = pipeline.get_by_name("sink")

    # Everything runs in a GLib main loop, as GStreamer applications do: a thread blocked in
    # a pull would not see Ctrl-C until a packet came. appsink's streaming thread only hands
    # each sample to the loop; SIGINT and SIGTERM quit it.
    loop = GLib.MainLoop()
    status = [0]
    alphabet = [None]
    idle_timeout = [0]

    def quit_loop():
        loop.quit()
        return GLib.SOURCE_REMOVE

    def restart_idle_timeout():
        if args.idle_exit <= 0:
            return
        if idle_timeout[0]:
            GLib.source_remove(idle_timeout[0])
        idle_timeout[0] = GLib.timeout_add(int(args.idle_exit * 1000), quit_loop)

    def on_event(sample):
        restart_idle_timeout()
        if alphabet[0] is None:
            caps = sample.get_caps().get_structure(0)
            name = caps.get_string("alphabet") or args.alphabet or GstPfap.ALPHABET_ARPABET
            alphabet[0] = GstPfap.Alphabet.find(name)
            if alphabet[0] is None:
                print("unknown alphabet %s: symbols shown as numbers" % name, file=sys.stderr)
        buffer = sample.get_buffer()
        try:
            event = GstPfap.Event.new_from_buffer(buffer)
        except GLib.Error as e:
            print("dropped: %s" % e.message, file=sys.stderr)
            return GLib.SOURCE_REMOVE
        print(describe(event, buffer.pts, alphabet[0]), flush=True)
        return GLib.SOURCE_REMOVE

    def on_new_sample(appsink):  # appsink's streaming thread
        GLib.idle_add(on_event, appsink.pull_sample())
        return Gst.FlowReturn.OK

    def on_error(bus, message):
        error, _ = message.parse_error()
        print("error: %s" % error.message, file=sys.stderr)
        status[0] = 1
        loop.quit()

    sink.connect("new-sample", on_new_sample)
    bus = pipeline.get_bus()
    bus.add_signal_watch()
    bus.connect("message::error", on_error)
    for signum in (signal.SIGINT, signal.SIGTERM):
        GLib.unix_signal_add(GLib.PRIORITY_DEFAULT, signum, quit_loop)
    pipeline.set_state(Gst.State.PLAYING)
    print("listening on %s:%d" % (args.address, args.port), flush=True)
    restart_idle_timeout()
    loop.run()
    pipeline.set_state(Gst.State.NULL)
    bus.remove_signal_watch()
    return status[0]


if __name__ == "__main__":
    sys.exit(main())
