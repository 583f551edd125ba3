#!/usr/bin/gjs
// SPDX-License-Identifier: LGPL-2.1-or-later
// Prints the phonemes of a PFAP RTP stream received on UDP, in JavaScript (gjs): the same
// GstPfap-1.0 API as examples/python/pfap-receiver.py, through GObject-Introspection.
//
//   udpsrc ! rtpjitterbuffer max-dropout-time=0 max-misorder-time=0 ! rtppfapdepay ! appsink
//
// (the jitterbuffer's windows fixed, so that a flood of spoofed packets cannot stall it:
// docs/security.md, "Floods").
//
// Usage: pfap-receiver.js [--port PORT] [--idle-exit SECONDS]; Ctrl-C ends it.
// From a build tree, set GI_TYPELIB_PATH, LD_LIBRARY_PATH and GST_PLUGIN_PATH (docs/apps.md).
imports.gi.versions.Gst = '1.0';
imports.gi.versions.GstApp = '1.0';
imports.gi.versions.GstPfap = '1.0';
const {GLib, Gst, GstApp, GstPfap} = imports.gi;

const USAGE = `usage: pfap-receiver.js [-h] [--port PORT] [--idle-exit SECONDS]

Prints the phonemes of a PFAP RTP stream received on UDP.

options:
  -h, --help           show this help message and exit
  --port PORT          UDP port on 127.0.0.1 (default 5004)
  --idle-exit SECONDS  exit after this many seconds without an event (default: never)`;

function parseArgs(argv) {
    const args = {port: 5004, idleExit: 0};
    for (let i = 0; i < argv.length; i++) {
        const value = () => {
            const v = Number(argv[++i]);
            if (!Number.isFinite(v))
                throw new Error(`${argv[i - 1]} needs a number`);
            return v;
        };
        if (argv[i] === '-h' || argv[i] === '--help') {
            print(USAGE);
            return null;
        } else if (argv[i] === '--port') {
            args.port = value();
        } else if (argv[i] === '--idle-exit') {
            args.idleExit = value();
        } else {
            throw new Error(`unknown argument ${argv[i]}\n${USAGE}`);
        }
    }
    return args;
}

function main(argv) {
    const args = parseArgs(argv);
    if (args === null)
        return 0;
    Gst.init(null);
    const pipeline = Gst.parse_launch(
        'udpsrc name=src address=127.0.0.1 caps="application/x-rtp,media=application,' +
        'encoding-name=PFAP,clock-rate=44100" ! rtpjitterbuffer max-dropout-time=0 ' +
        'max-misorder-time=0 ! rtppfapdepay ! ' +
        `appsink name=sink caps=${GstPfap.CAPS} sync=false`);
    pipeline.get_by_name('src').port = args.port;
    const sink = pipeline.get_by_name('sink');
    pipeline.set_state(Gst.State.PLAYING);
    print(`listening on 127.0.0.1:${args.port}`);

    // gjs cannot run JavaScript on appsink's streaming thread (no new-sample handler), so the
    // main thread pulls, a tenth of a second at a time, and between pulls lets GLib dispatch
    // SIGINT and SIGTERM: a pull that waited for ever would not see Ctrl-C until a packet came.
    let quit = false;
    for (const signal of [2 /* SIGINT */, 15 /* SIGTERM */]) {
        GLib.unix_signal_add(GLib.PRIORITY_DEFAULT, signal, () => {
            quit = true;
            return GLib.SOURCE_REMOVE;
        });
    }
    const context = GLib.MainContext.default();
    const idleUs = args.idleExit * 1e6;
    let lastEvent = GLib.get_monotonic_time();
    let alphabet = null;
    while (!quit) {
        const sample = sink.try_pull_sample(100 * Gst.MSECOND);
        while (context.iteration(false)) { /* dispatch what is pending */ }
        if (sample === null) {
            if (idleUs > 0 && GLib.get_monotonic_time() - lastEvent >= idleUs)
                break;
            continue;
        }
        lastEvent = GLib.get_monotonic_time();
        if (alphabet === null) {
            const name = sample.get_caps().get_structure(0).get_string('alphabet');
            alphabet = GstPfap.Alphabet.find(name ?? GstPfap.ALPHABET_ARPABET);
        }
        const buffer = sample.get_buffer();
        let event;
        try {
            event = GstPfap.Event.new_from_buffer(buffer);
        } catch (e) {
            printerr(`dropped: ${e.message}`);
            continue;
        }
        const time = (buffer.pts / Gst.SECOND).toFixed(3);
        if (event.get_kind() === GstPfap.EventKind.PHONEME) {
            const symbol = event.get_symbol();
            const name = alphabet?.get_phoneme_name(symbol) ?? `#${symbol}`;
            print(`${time} phoneme ${name} ${event.get_duration_ms()} ms, ` +
                  `${event.get_n_faps()} FAPs`);
        } else {
            print(`${time} state event, ${event.get_n_faps()} FAPs`);
        }
        for (const fap of event.get_faps())
            print(`    FAP ${fap.index} -> ${fap.amplitude} over ${fap.transition_ms} ms`);
    }
    pipeline.set_state(Gst.State.NULL);
    return 0;
}

imports.system.exit(main(ARGV));
