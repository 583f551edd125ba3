#!/usr/bin/python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""tools/pfap-web stopped by SIGTERM with sessions open (issue 28; docs/web.md, "Stopping"):
N aiortc peers (as tests/web/pfap_web_load.py) connect, say they play and wait mid-sentence,
each until its first PFAP packet; then every second peer leaves (closes its peer connection and
WebSocket) as the server gets SIGTERM, so that sessions closing as their peers leave and
sessions stopped by the server meet. RUNS times with --stop-timeout=10: the server must exit 0
with "pfap-web: stopped" within BOUND_S, and every peer that stayed must see its WebSocket
closed. Then once the same with 2N sessions whose peers ask for a short text each time one
starts, a second after the first packets, so that texts end and start as the stop closes the
sessions. Then once with --stop-timeout=0.001, shorter than any stop: it must exit 3 within
BOUND_S with the line naming the session it was stopping and those not stopped yet (or the
main loop, if the signal came before the stop began). The server must print no GLib CRITICAL.
A server that does not exit within 15 s of its deadline has its threads' stacks printed (gdb)
and is killed. Exits 1 if any of it fails.

    pfap_web_stop.py [N] [RUNS]   (default 8 1; PFAP_WEB names the server; as root)

In a network namespace with lo and a veth pair, as tests/web/pfap_web_load.py."""
import asyncio
import os
import re
import subprocess
import sys
import time

from pfap_web_load import (enter_network_namespace, playing_peer, skip_opus_decoding, stacks,
                           start_server)

TEXT = ' '.join(['One, <FAP 3 100 400 1> two, three, four, five, six, seven, eight.'] * 6)
# Short texts, each asked for as the one before starts: texts end and start as the stop closes
# the sessions one by one.
SHORT_TEXT = 'One, <FAP 3 100 400 1> two.'
# The server's default deadline: the sanitizer build's stops of 10 sessions took 1.3 to 3.2 s.
# PFAP_WEB_STOP_TIMEOUT gives another: the sanitizer build's (meson.build), whose stop of 20
# sessions saying short texts took 14 s alone and more than 30 s beside another test.
STOP_TIMEOUT_S = float(os.environ.get('PFAP_WEB_STOP_TIMEOUT', '10'))
# The deadline, and what the process's end may take after it.
BOUND_S = STOP_TIMEOUT_S + 5


async def open_session(port, first_packet, leave, again):
    """A playing peer (pfap_web_load.playing_peer) that waits until the server closes its
    WebSocket (True) or `leave` is set (False)."""
    try:
        await playing_peer(port, first_packet, leave, again=again)
        return False
    except (ConnectionError, asyncio.IncompleteReadError):
        return True
    finally:
        first_packet.set()  # the others go on


# A GLib CRITICAL of GStreamer's, not of the stop: a data race in gst-plugins-good 1.22.0's
# rtpsession (its RTCP thread walks the session's sources while an RTCP packet adds one),
# fixed in 1.22.3, which Debian 12 does not have. About 1 stop in 30 in the sanitizer build,
# before the signal too (docs/web.md, "Stopping"). Printed, not failed on; any other fails.
KNOWN_CRITICAL = "g_hash_table_foreach: assertion 'version == hash_table->version' failed"


def criticals(err):
    """The GLib CRITICAL lines of `err` other than KNOWN_CRITICAL."""
    return [line for line in err.splitlines()
            if 'CRITICAL' in line and KNOWN_CRITICAL not in line]


async def run(sessions, stop_timeout_s, short=False):
    """One server with `sessions` open, stopped; its exit status and what it printed, or None
    if it took longer than BOUND_S, not every peer that stayed saw its WebSocket closed, or it
    printed a GLib CRITICAL (but KNOWN_CRITICAL). `short`: the peers ask for SHORT_TEXT again
    and again, and the signal comes a second after the first packets."""
    server, port = start_server([f'--text={SHORT_TEXT if short else TEXT}',
                                 f'--stop-timeout={stop_timeout_s}'])
    packets = [asyncio.Event() for _ in range(sessions)]
    leave = [asyncio.Event() for _ in range(sessions)]
    again = SHORT_TEXT if short else None
    peers = [asyncio.ensure_future(open_session(port, p, q, again))
             for p, q in zip(packets, leave)]
    try:
        await asyncio.wait_for(asyncio.gather(*(p.wait() for p in packets)), 60)
    except BaseException:
        server.kill()  # peers that never had their first packet: no server left running
        server.wait()
        raise
    if short:
        await asyncio.sleep(1)
    mid_sentence = sum(not p.done() for p in peers)
    for q in leave[1::2]:
        q.set()
    await asyncio.sleep(0)  # the leaving peers start to close
    stopping = time.monotonic()
    server.terminate()
    loop = asyncio.get_running_loop()
    try:
        out, err = await loop.run_in_executor(None, lambda: server.communicate(timeout=BOUND_S + 15))
    except subprocess.TimeoutExpired:
        stacks(server.pid)
        server.kill()
        out, err = server.communicate()
    took = time.monotonic() - stopping
    closed = await asyncio.wait_for(asyncio.gather(*peers, return_exceptions=True), 30)
    told, staying = sum(c is True for c in closed[::2]), len(closed[::2])
    print(f'{sessions} sessions, {mid_sentence} mid-sentence at SIGTERM'
          f'{" (short texts, one after another)" if short else ""}, --stop-timeout='
          f'{stop_timeout_s}: pfap-web exited {server.returncode} {took:.1f} s after it; {told} '
          f'of the {staying} peers that stayed saw their WebSocket closed')
    if KNOWN_CRITICAL in err:
        print(f'the known GLib CRITICAL (KNOWN_CRITICAL), not failed on:\n{err[-3000:]}',
              file=sys.stderr)
    if criticals(err):
        print(f'GLib CRITICALs:\n{err[-3000:]}', file=sys.stderr)
        return None
    if took > BOUND_S or told != staying:
        print(err[-3000:], file=sys.stderr)
        return None
    return server.returncode, out, err


async def main():
    sessions = int(sys.argv[1]) if len(sys.argv) > 1 else 8
    runs = int(sys.argv[2]) if len(sys.argv) > 2 else 1
    ok = True
    for _ in range(runs):
        r = await run(sessions, STOP_TIMEOUT_S)
        if r is None or r[0] != 0 or 'pfap-web: stopped' not in r[1]:
            ok = False
            print(f'not stopped cleanly: {r and r[0]}\n{r and r[2][-3000:]}', file=sys.stderr)
    # Texts ending and starting while the stop closes twice as many sessions: the calls their
    # streaming threads post must still run on the main thread, after their session is closed,
    # not on those threads beside close_session (GLib CRITICALs, a speaker disposed in PAUSED,
    # stops that hung: 5 of 7 such stops of 20 sessions in the sanitizer build before the fix,
    # 0 of 4 of 10; docs/web.md, "Stopping").
    r = await run(2 * sessions, STOP_TIMEOUT_S, short=True)
    if r is None or r[0] != 0 or 'pfap-web: stopped' not in r[1]:
        ok = False
        print(f'not stopped cleanly with short texts: {r and r[0]}\n{r and r[2][-3000:]}',
              file=sys.stderr)
    # A deadline too short for any stop: the server gives up on the sessions it has not
    # stopped, names them, and exits 3.
    r = await run(sessions, 0.001)
    # At the signal the main thread may still be in the main loop (in a slow build), or already
    # stopping a session.
    gave_up = r is not None and re.search(
        r'pfap-web: not stopped within 0.001 s \(--stop-timeout\), at (the main loop|session '
        r"\d+'s pipeline going to NULL(; sessions? [\d, ]+ not stopped yet)?); exiting anyway",
        r[2])
    if r is None or r[0] != 3 or not gave_up:
        ok = False
        print(f'did not give up as it should: {r and r[0]}\n{r and r[2][-3000:]}', file=sys.stderr)
    else:
        print(gave_up.group(0))
    if not ok:
        sys.exit(1)


if __name__ == '__main__':
    enter_network_namespace()
    skip_opus_decoding()
    asyncio.run(main())
