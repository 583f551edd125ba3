#!/usr/bin/python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""Sessions that come and go against tools/pfap-web (issue 28): CYCLES sessions, CONCURRENT at
a time, each of one of KINDS in turn: n, one that never answers the offer (the server's
--connect-timeout closes it); a, one that answers the offer and leaves at once, while ICE has
yet to connect and webrtcbin may not yet have set the answer; m, one that connects, says it
plays and leaves mid-sentence (at its first PFAP packet); e, one that hears its text to the end
and leaves. After a warm-up (the first sessions load plugins and fill caches that stay), it
takes the server's file descriptors, threads and RSS; after the cycles, once the server has
closed every session, it takes them again. The server runs with GStreamer's leaks tracer,
which lists at exit every GstObject still alive. Exits 1 if a cycle did not end within
CYCLE_S or the server within 30 s of SIGTERM, if a session was left open (pfap-web prints
"session N opened" and "closed"), if any file descriptor or thread was left behind, or if any
object but dtlsdec's one shared DTLS agent (GStreamer's, made once per process for the
default certificate) outlived the sessions. RSS is printed, not checked: glibc's arenas grow
with the sessions open at once and keep what they took, so only a long run tells a leak from
that (scripts/bench churn, docs/performance.md).

    pfap_web_churn.py [CYCLES] [CONCURRENT] [KINDS]   (default 50 6 nme; PFAP_WEB names the
                                                      server; as root)

In a network namespace with lo and a veth pair, as tests/web/pfap_web_load.py."""
import asyncio
import os
import re
import subprocess
import sys
import threading
import time

from pfap_web_load import (WebSocket, answer_offer, enter_network_namespace, playing_peer,
                           rss_kib, skip_opus_decoding, stacks, start_server)

WARM_UP = 9
# A cycle takes about 1 s (3 to 8 s in the sanitizer build): one still going after CYCLE_S is
# stuck. The run then stops, and says where, within meson's timeout.
CYCLE_S = 30
# Alive at exit whatever the sessions did: dtlsdec keeps one agent for its generated
# certificate for the life of the process (gst-plugins-bad ext/dtls/gstdtlsdec.c).
ALIVE_ANYWAY = {'GstDtlsAgent': 1}
TEXT = 'One, <FAP 3 100 400 1> two, three, four, five, six.'


async def never_answers(port):
    ws = await WebSocket.connect(port)
    try:
        while True:  # until the server gives up on the answer and closes
            await ws.receive()
    except (ConnectionError, asyncio.IncompleteReadError):
        pass
    finally:
        ws.writer.close()


async def answers_and_leaves(port):
    """Leaves as soon as its answer is sent: the server has it, and the closed connection,
    at once (docs/performance.md, "The receive bin")."""
    from aiortc import RTCPeerConnection
    pc = RTCPeerConnection()
    ws = await WebSocket.connect(port)
    try:
        while (m := await ws.receive())['type'] != 'offer':
            pass
        await answer_offer(pc, ws, m)
        await ws.writer.drain()
    finally:
        await pc.close()
        ws.writer.close()


async def connects(port, to_the_end):
    """A playing peer (pfap_web_load.playing_peer) that leaves at its first PFAP packet
    (mid-sentence) or, `to_the_end`, at the text's end."""
    first_packet = asyncio.Event()
    await playing_peer(port, first_packet, asyncio.Event() if to_the_end else first_packet,
                       until=('done', 'error'))


async def cycle(port, kind):
    await asyncio.wait_for(never_answers(port) if kind == 'n' else answers_and_leaves(port)
                           if kind == 'a' else connects(port, kind == 'e'), CYCLE_S)


def runs_pfap_espeak(pid):
    """Whether the server has started pfap-espeak, its child for the life of the server."""
    children = []
    for task in os.listdir(f'/proc/{pid}/task'):
        try:
            with open(f'/proc/{pid}/task/{task}/children') as f:
                children += f.read().split()
        except OSError:
            pass
    for child in children:
        try:
            with open(f'/proc/{child}/comm') as f:
                if f.read().strip() == 'pfap-espeak':
                    return True
        except OSError:
            pass
    return False


def figures(pid):
    return (len(os.listdir(f'/proc/{pid}/fd')), len(os.listdir(f'/proc/{pid}/task')),
            rss_kib(pid, 'VmRSS'))


async def main():
    cycles = int(sys.argv[1]) if len(sys.argv) > 1 else 50
    concurrent = int(sys.argv[2]) if len(sys.argv) > 2 else 6
    kinds = sys.argv[3] if len(sys.argv) > 3 else 'nme'
    if not kinds or set(kinds) - set('nmea'):
        raise SystemExit(f'KINDS is some of n, m, e and a: {kinds}')
    server, port = start_server([f'--text={TEXT}', '--connect-timeout=1'],
                                env=dict(os.environ, GST_TRACERS='leaks', GST_DEBUG_NO_COLOR='1',
                                         GST_DEBUG='*:1,GST_TRACER:7'))
    opened, closed = set(), set()
    # The server's stderr: its last lines, and a sanitizer's report whole from its first line
    # (a rare leak's stacks are what tell where it comes from).
    alive, err, report = {}, [], []

    def follow():
        for out in server.stdout:
            if m := re.match(r'pfap-web: session (\d+) (opened|closed)', out):
                (opened if m.group(2) == 'opened' else closed).add(int(m.group(1)))

    def follow_errors():  # read as it comes, so that the server never blocks on a full pipe
        for out in server.stderr:
            if m := re.search(r'object-alive, type-name=\(string\)(\w+)', out):
                alive[m.group(1)] = alive.get(m.group(1), 0) + 1
            elif 'GST_TRACER' in out:
                pass
            elif report or re.match(r'==\d+==ERROR: \w+Sanitizer', out):
                report.append(out)
            else:
                err.append(out)
                del err[:-20]
    followers = [threading.Thread(target=f, daemon=True) for f in (follow, follow_errors)]
    for f in followers:
        f.start()

    stuck = []

    async def run(first, count):
        queue = iter(range(first, first + count))
        failures, begun = [], [0]

        async def worker():
            for n in queue:
                if stuck:
                    return
                begun[0] += 1
                kind = kinds[n % len(kinds)]
                try:
                    await cycle(port, kind)
                except asyncio.TimeoutError:
                    stuck.append(f'cycle {n} ({kind}) still going after {CYCLE_S} s')
                except Exception as e:  # noqa: BLE001 (counted; the server is what is checked)
                    failures.append(f'cycle {n} ({kind}): {type(e).__name__}: {e}')
        await asyncio.gather(*(worker() for _ in range(concurrent)))
        return failures, begun[0]

    def died():
        for f in followers:
            f.join(timeout=10)
        print(f'pfap-web died (exit {server.returncode}) after {len(opened)} sessions:\n'
              + ''.join(err + report), file=sys.stderr)
        sys.exit(1)

    async def settled(target=(0, 0)):
        """Once every session the server opened is closed and its file descriptors and threads
        are down to `target` (its threads' pools let idle threads go after a while: 20 s at
        most), its figures."""
        end = time.monotonic() + 20
        while time.monotonic() < end:
            if server.poll() is not None:
                died()
            now = figures(server.pid)
            if (not opened - closed and len(closed) >= started and now[0] <= target[0]
                    and now[1] <= target[1]):
                break
            await asyncio.sleep(0.2)
        return figures(server.pid)

    # aiortc's own tasks of a peer connection closed while it connects fail afterwards, with
    # no one to await them: counted, not printed (the server is what is checked).
    orphans = [0]
    asyncio.get_running_loop().set_exception_handler(
        lambda loop, context: orphans.__setitem__(0, orphans[0] + 1))

    # The server's first synthesis starts pfap-espeak, which then lives as long as the server
    # (docs/tts.md) with a socket of the server's: a session that speaks comes first, alone, or
    # in a slow run (the sanitizer build) the warm-up's sessions could close before speaking
    # and the socket would be counted as left behind. That session can fail too in such a run
    # (a fresh root's sanitizer build once counted 8 descriptors before and 9 after), so it is
    # repeated, up to 3 times, until pfap-espeak runs.
    speaking = 0
    if set(kinds) & set('me'):
        while speaking < 3 and not runs_pfap_espeak(server.pid):
            speaking += 1
            try:
                await cycle(port, 'e')
            except Exception:  # noqa: BLE001 (as run()'s warm-up failures: the server is checked)
                pass
    await run(speaking, WARM_UP)
    started = speaking + WARM_UP
    before = await settled((1 << 30, 1 << 30))
    start = time.monotonic()
    failures, begun = await run(started, cycles)  # fewer begun than asked: a cycle was stuck
    took = time.monotonic() - start
    started += cycles
    after = await settled(before)
    left_open = sorted(opened - closed)
    server.terminate()
    try:
        server.wait(timeout=30)
    except subprocess.TimeoutExpired:
        stuck.append('pfap-web still running 30 s after SIGTERM')
        stacks(server.pid)
        server.kill()
        server.wait()
    for f in followers:
        f.join(timeout=10)
    leaked = {k: n - ALIVE_ANYWAY.get(k, 0) for k, n in alive.items()
              if n > ALIVE_ANYWAY.get(k, 0)}
    for f in failures[:10]:
        print(f)
    print(f'{begun} of {cycles} cycles of kinds {kinds} ({concurrent} at a time, '
          f'{len(failures)} client errors, {orphans[0]} in aiortc\'s tasks) in {took:.1f} s '
          f'after {speaking + WARM_UP} to warm up; pfap-web opened {len(opened)} sessions, closed '
          f'{len(closed)}; before: {before[0]} file descriptors, {before[1]} threads, RSS '
          f'{before[2]} KiB; after: {after[0]}, {after[1]}, {after[2]} KiB '
          f'({(after[2] - before[2]) / max(begun, 1):+.1f} KiB per cycle); GstObjects alive at '
          f'exit besides dtlsdec\'s agent: {leaked or "none"}; pfap-web exited {server.returncode}')
    ok = (not stuck and not left_open and after[0] <= before[0] and after[1] <= before[1]
          and not leaked and len(opened) == started and server.returncode == 0)
    if not ok:
        print('; '.join(stuck + [f'left behind: sessions {left_open[:20]}']), file=sys.stderr)
        print(''.join(err + report), file=sys.stderr)
        sys.exit(1)


if __name__ == '__main__':
    enter_network_namespace()
    skip_opus_decoding()
    asyncio.run(main())
