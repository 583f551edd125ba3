#!/usr/bin/python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""aiortc viewers of the talking head broadcast through Janus (issue 28, "Measured, side by
side"; docs/web.md, "Broadcast through Janus"): Janus with the project's configuration
(scripts/janus-config), N viewers that are real WebRTC peers but not browsers (Debian's
python3-aiortc), and tools/pfap-broadcast as the sender. Each viewer talks to Janus's HTTP
API as janus.js does: create a session, attach the streaming plugin, "watch" mountpoint 1,
answer Janus's offer with "start", and follow the session's events by long polls. Once every
viewer's data channel is open the sender says TEXT. Each viewer checks that the Opus track
brings audio and the data channel every PFAP packet the sender sent (its count and last
sequence number from the sender's "done", which ends the data stream), and that the FAP state
those packets leave equals the sender's (decoded by web/src/ in node, pfap_web_state.mjs,
as pfap_web_load.py does). Prints one line per viewer that is not whole and a summary, with
Janus's CPU per viewer while the sender speaks, its fds and threads before, at the peak and
after the viewers left (with --row, one Markdown table row for scripts/bench); exits 1 if a
viewer is not whole. Janus's first viewer starts threads and fds that stay (GLib's worker
thread and a pool, measured in web-janus-broadcast, which checks Janus for leaks): the
figures after are printed, not judged.

    janus_load.py [--row] [N] [TEXT]   (PFAP_BROADCAST names the sender, PFAP_SOURCE_ROOT
                                        the source tree, NODE node; as root)

It runs in pfap_web_load.py's network namespace (lo and a veth pair, 10.99.0.1 and .2):
Janus gathers no ICE candidate on a loopback interface, and aiortc offers none there either;
Janus's ICE uses 10.99.0.1. No packet leaves the namespace."""
import asyncio
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import time

import pfap_web_load as load

JANUS_PORT = 8088
AUDIO_PORT = 5002
DATA_PORT = 5004
MOUNTPOINT = 1
ICE_ADDRESS = '10.99.0.1'
JSON_FIRST_BYTE = ord('{')  # the sender's JSON messages beside the PFAP packets
LEVEL_MESSAGE_TYPE = 0x01  # and its level messages (tools/speech_level.h)
SOURCE_ROOT = os.environ.get('PFAP_SOURCE_ROOT') or os.path.join(
    os.path.dirname(os.path.abspath(__file__)), '..', '..')


async def http(method, path, body=None, timeout_s=40):
    """One request to Janus's HTTP API on 127.0.0.1 (HTTP/1.0: a connection each, no chunks); its
    JSON answer."""
    data = json.dumps(body).encode() if body is not None else b''
    reader, writer = await asyncio.open_connection('127.0.0.1', JANUS_PORT)
    try:
        writer.write((f'{method} {path} HTTP/1.0\r\nHost: 127.0.0.1\r\nConnection: close\r\n'
                      f'Content-Type: application/json\r\nContent-Length: {len(data)}\r\n\r\n'
                      ).encode() + data)
        async with asyncio.timeout(timeout_s):
            answer = await reader.read()
    finally:
        writer.close()
    head, _, payload = answer.partition(b'\r\n\r\n')
    if b' 200 ' not in head.split(b'\r\n')[0]:
        raise ConnectionError(head.split(b'\r\n')[0].decode(errors='replace'))
    return json.loads(payload)


class JanusSession:
    """A session with Janus and its handle on the streaming plugin; its events by long poll."""

    @classmethod
    async def open(cls):
        self = cls()
        self.events = asyncio.Queue()
        created = await http('POST', '/janus', {'janus': 'create', 'transaction': 'c'})
        self.path = f"/janus/{created['data']['id']}"
        attached = await http('POST', self.path, {'janus': 'attach', 'transaction': 'a',
                                                  'plugin': 'janus.plugin.streaming'})
        self.handle = f"{self.path}/{attached['data']['id']}"
        self.poller = asyncio.ensure_future(self.poll())
        return self

    async def poll(self):
        while True:
            for event in await http('GET', f'{self.path}?maxev=10'):
                if event.get('janus') != 'keepalive':
                    await self.events.put(event)

    async def message(self, body, jsep=None):
        request = {'janus': 'message', 'transaction': 'm', 'body': body}
        if jsep:
            request['jsep'] = jsep
        answer = await http('POST', self.handle, request)
        if answer.get('janus') == 'error':
            raise ConnectionError(answer['error'])

    async def event_with_jsep(self):
        while True:
            event = await self.events.get()
            data = event.get('plugindata', {}).get('data', {})
            if 'error' in data:
                raise ConnectionError(data['error'])
            if 'jsep' in event:
                return event['jsep']

    async def close(self):
        """Leaves as janus.js does on unload: destroys the session (and so its handle)."""
        self.poller.cancel()
        await http('POST', self.path, {'janus': 'destroy', 'transaction': 'd'})


async def viewer(number, all_open, deadline_s):
    """One viewer: watches the mountpoint, reports its data channel open to `all_open` (a
    list of events, its own at `number - 1`), collects the data stream until "done"."""
    from aiortc import RTCPeerConnection, RTCSessionDescription

    result = {'session': number, 'audio_packets': 0, 'packets': 0, 'last_seq': None,
              'sender': None, 'error': None, 'messages': []}
    pc = RTCPeerConnection()
    done = asyncio.Event()
    session = None

    # The viewer opens a data channel, as janus.js does; Janus 1.1.2 sends the mountpoint's data
    # on it (it has no channel of its own labelled "pfap" for a viewer who opened one).
    channel = pc.createDataChannel('JanusDataChannel')
    channel.on('open', all_open[number - 1].set)

    @channel.on('message')
    def on_message(message):
        if message[0] == JSON_FIRST_BYTE:
            m = json.loads(message)
            if m['type'] == 'done':
                result['sender'] = m
                done.set()
            return
        if message[0] == LEVEL_MESSAGE_TYPE:
            return
        result['packets'] += 1
        result['last_seq'] = struct.unpack('!H', message[2:4])[0]
        result['messages'].append(message)

    try:
        async with asyncio.timeout(deadline_s):
            result['stage'] = 'session'
            session = await JanusSession.open()
            result['stage'] = 'watch'
            await session.message({'request': 'watch', 'id': MOUNTPOINT})
            offer = await session.event_with_jsep()
            result['stage'] = 'answer'
            await pc.setRemoteDescription(RTCSessionDescription(offer['sdp'], offer['type']))
            await pc.setLocalDescription(await pc.createAnswer())
            await session.message({'request': 'start'},
                                  {'type': 'answer', 'sdp': pc.localDescription.sdp})
            result['stage'] = 'the data channel'
            await all_open[number - 1].wait()
            result['stage'] = 'the data stream'
            await done.wait()
            result['audio_packets'] = await load.audio_packets(pc)
    except Exception as e:  # noqa: BLE001 (reported per viewer)
        result['error'] = f"{type(e).__name__} waiting for {result['stage']}: {e}"
        all_open[number - 1].set()  # the others go on
    finally:
        await pc.close()
        if session:
            await session.close()
    return result


def start_janus(tmp):
    config = os.path.join(tmp, 'janus')
    subprocess.run([os.path.join(SOURCE_ROOT, 'scripts', 'janus-config'), config, str(JANUS_PORT),
                    str(AUDIO_PORT), str(DATA_PORT), ICE_ADDRESS], check=True)
    return subprocess.Popen(['janus', '-F', config, '-C', os.path.join(config, 'janus.jcfg')],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)


async def wait_for_janus(janus):
    for _ in range(100):
        try:
            await http('GET', '/janus/info')
            return
        except OSError:
            if janus.poll() is not None:
                raise SystemExit(f'janus exited: {janus.stderr.read()[-2000:]}')
            await asyncio.sleep(0.1)
    raise SystemExit('Janus does not answer')


def resources(pid):
    """Janus's fds (less TCP connections the peer closed, the long polls it has yet to
    answer) and threads."""
    closed = set()
    for line in open(f'/proc/{pid}/net/tcp').read().split('\n')[1:]:
        f = line.split()
        if len(f) > 9 and f[3] == '08':  # CLOSE_WAIT
            closed.add(f'socket:[{f[9]}]')
    fds = 0
    for fd in os.listdir(f'/proc/{pid}/fd'):
        try:
            fds += os.readlink(f'/proc/{pid}/fd/{fd}') not in closed
        except OSError:
            pass
    return fds, len(os.listdir(f'/proc/{pid}/task'))


def cpu_s(pid):
    fields = open(f'/proc/{pid}/stat').read().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


async def main():
    args = sys.argv[1:]
    row = '--row' in args
    args = [a for a in args if a != '--row']
    count = int(args[0]) if args else 5
    text = args[1] if len(args) > 1 else 'One, two, three. <FAP 2 1 40 0 0 800 3> Four, five.'
    with tempfile.TemporaryDirectory(prefix='pfap-janus-') as tmp:
        janus = start_janus(tmp)
        try:
            await wait_for_janus(janus)
            idle = resources(janus.pid)
            peak = list(idle)
            cpu_all_start = cpu_s(janus.pid)
            all_open = [asyncio.Event() for _ in range(count)]
            viewers = asyncio.gather(*(viewer(i + 1, all_open, 60 + count) for i in range(count)))
            for e in all_open:
                await e.wait()
            peak = [max(a, b) for a, b in zip(peak, resources(janus.pid))]
            cpu_start, start = cpu_s(janus.pid), time.monotonic()
            sender = subprocess.Popen([os.environ['PFAP_BROADCAST'], f'--audio-port={AUDIO_PORT}',
                                       f'--data-port={DATA_PORT}', f'--text={text}'],
                                      stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            out, err = await asyncio.to_thread(sender.communicate)
            cpu, took = cpu_s(janus.pid) - cpu_start, time.monotonic() - start
            results = await viewers
            cpu_all = cpu_s(janus.pid) - cpu_all_start  # sessions set up, the text, closing
            if sender.returncode != 0:
                raise SystemExit(f'pfap-broadcast exited {sender.returncode}: {err[-2000:]}')
            sent = json.loads(out.strip().split('\n')[-1])
            # Janus frees a session's ICE thread and sockets a few seconds after it is destroyed.
            left = resources(janus.pid)
            for _ in range(50):
                if left[0] <= idle[0] and left[1] <= idle[1]:
                    break
                await asyncio.sleep(0.2)
                left = resources(janus.pid)
        finally:
            janus.terminate()
            janus_status = janus.wait(timeout=30)
    load.decode_states(results)
    good = sum(load.whole(r) and r['sender'] == sent for r in results)
    if row:
        print(f'| {count} | {good} | {cpu / took / count * 100:.2f} % | {cpu * 1000 / count:.1f} ms | '
              f'{cpu_all * 1000 / count:.1f} ms | '
              f'{(peak[0] - idle[0]) / count:.1f} | {(peak[1] - idle[1]) / count:.1f} | '
              f'{left[0] - idle[0]}, {left[1] - idle[1]} |')
    for r in results:
        if load.whole(r) and r['sender'] == sent:
            continue
        print(f"viewer {r['session']}: NOT WHOLE: {r['audio_packets']} Opus packets, {r['packets']} "
              f"of {sent['packets']} PFAP packets, last sequence number {r['last_seq']} of "
              f"{sent['lastSequenceNumber']}, FAP state "
              f"{'equal to' if r['state_equal'] else 'differs from'} the sender's"
              + (f", {r['error']}" if r['error'] else ''))
    if not row:
        print(f'Janus: CPU {cpu:.2f} s while the sender spoke ({took:.1f} s): '
              f'{cpu / took / count * 100:.2f} % of a core, {cpu * 1000 / count:.1f} ms per viewer; '
              f'{cpu_all * 1000 / count:.1f} ms per viewer in all (set up, the text, leaving); '
              f'fds and threads {idle[0]} and {idle[1]} idle, at most {peak[0]} and {peak[1]} '
              f'with the viewers, {left[0]} and {left[1]} after they left')
        print(f'{good} of {count} viewers whole ({sent["packets"]} PFAP packets, '
              f'{sent["phonemes"]} phonemes); Janus exited {janus_status} on SIGTERM')
    if good != count or janus_status != 0:
        sys.exit(1)


if __name__ == '__main__':
    if shutil.which('janus') is None:
        print('SKIP: no janus (scripts/install-deps installs it)')
        sys.exit(77)
    load.enter_network_namespace()
    load.skip_opus_decoding()
    asyncio.run(main())
