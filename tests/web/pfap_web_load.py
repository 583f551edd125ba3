#!/usr/bin/python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""A load generator for tools/pfap-web (issue 28, "Sessions per server"): N sessions, each a
real WebRTC peer (Debian's python3-aiortc) but not a browser, opened at once. Each answers
the offer, says it plays, and checks that the Opus track brings audio and the data channel
every PFAP packet the server sent for its text (the count and the last sequence number of the
server's "done" message; nothing is dropped; the audio is counted in Opus RTP packets), and
that the FAP state those packets leave equals the sender's (the "done" message's settled
values; the packets decoded by web/src/ in node, tests/web/pfap_web_state.mjs). Each also
times every packet's arrival against its RTP timestamp: the worst lateness (lateness():
against the stream's most punctual packet) and the share later than LATE_S say whether the
server keeps real time. Prints one line per session and a summary (with --row, one Markdown
table row for scripts/bench); exits 1 if a session is not whole.

    pfap_web_load.py [--row] [--threads] [N] [TEXT]   (PFAP_WEB names the server, NODE node;
                                                       as root)

--threads adds where the server's CPU time went, by thread name (GStreamer names a streaming
thread after its element and pad), sampled every 0.5 s.

It runs in a network namespace of its own (unshare -n): aiortc leaves loopback addresses
out of its ICE candidates, so the namespace gets a veth pair, both ends inside it with
addresses that exist only there (10.99.0.1 and .2); aiortc offers those and reaches the
server's 127.0.0.1 from them. No packet leaves the namespace."""
import asyncio
import base64
import ipaddress
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import time

# A packet later than this after its time (lateness()) is late:
# beyond what a WebRTC jitter buffer absorbs for audio. PFAP packets leave the server 400 ms
# ahead of their audio (kPfapLead in tools/pfap-web.cc), so theirs is the stricter reading.
LATE_S = 0.1
AUDIO_CLOCK_RATE = 48000
PFAP_CLOCK_RATE = 44100


def enter_network_namespace():
    if os.environ.get('PFAP_WEB_NETNS') == '1':
        return
    try:
        import aiortc  # noqa: F401
    except ImportError:
        print('SKIP: no aiortc (scripts/install-deps installs python3-aiortc)')
        sys.exit(77)
    if os.geteuid() != 0 or shutil.which('unshare') is None or shutil.which('ip') is None:
        print('SKIP: needs root, unshare and ip (a network namespace with lo and a veth pair)')
        sys.exit(77)
    os.environ['PFAP_WEB_NETNS'] = '1'
    setup = ('ip link set lo up && ip link add pfap0 type veth peer name pfap1 && '
             'ip addr add 10.99.0.1/24 dev pfap0 && ip addr add 10.99.0.2/24 dev pfap1 && '
             'ip link set pfap0 up && ip link set pfap1 up && exec "$0" "$@"')
    os.execvp('unshare', ['unshare', '-n', 'sh', '-c', setup, sys.executable, *sys.argv])


class WebSocket:
    """Just enough of a WebSocket client on asyncio streams: text messages."""

    @classmethod
    async def connect(cls, port):
        self = cls()
        self.reader, self.writer = await asyncio.open_connection('127.0.0.1', port)
        key = base64.b64encode(os.urandom(16)).decode()
        self.writer.write((f'GET /ws HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\n'
                           f'Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n'
                           'Sec-WebSocket-Version: 13\r\n\r\n').encode())
        head = await self.reader.readuntil(b'\r\n\r\n')
        if b' 101 ' not in head.split(b'\r\n')[0]:
            raise RuntimeError(head.split(b'\r\n')[0].decode())
        return self

    def send(self, message):
        data = json.dumps(message).encode()
        mask = os.urandom(4)
        size = len(data)
        header = bytes([0x81]) + (bytes([0x80 | size]) if size < 126 else
                                  bytes([0x80 | 126]) + struct.pack('!H', size) if size < 65536
                                  else bytes([0x80 | 127]) + struct.pack('!Q', size))
        self.writer.write(header + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(data)))

    async def receive(self):
        while True:
            first, second = await self.reader.readexactly(2)
            size = second & 0x7f
            if size == 126:
                size = struct.unpack('!H', await self.reader.readexactly(2))[0]
            elif size == 127:
                size = struct.unpack('!Q', await self.reader.readexactly(8))[0]
            payload = await self.reader.readexactly(size)
            if first & 0x0f == 8:
                raise ConnectionError(f'closed by the server {payload[2:].decode(errors="replace")}')
            if first & 0x0f == 1:
                return json.loads(payload)


async def session(port, number, deadline_s):
    from aiortc import RTCPeerConnection, RTCSessionDescription

    result = {'session': number, 'audio_packets': 0, 'packets': 0, 'last_seq': None,
              'sender': None, 'error': None, 'messages': [], 'pfap_times': [],
              'audio_times': []}
    pc = RTCPeerConnection()
    ws = await WebSocket.connect(port)
    channel_open = asyncio.Event()

    @pc.on('datachannel')
    def on_datachannel(channel):
        channel_open.set()

        @channel.on('message')
        def on_message(message):
            result['packets'] += 1
            result['last_seq'] = struct.unpack('!H', message[2:4])[0]
            result['messages'].append(message)
            result['pfap_times'].append((time.monotonic(),
                                         struct.unpack('!I', message[4:8])[0]))

    try:
        async with asyncio.timeout(deadline_s):
            while True:
                m = await ws.receive()
                if m['type'] == 'offer':
                    await pc.setRemoteDescription(RTCSessionDescription(m['sdp'], 'offer'))
                    for receiver in pc.getReceivers():
                        receiver.pfap_arrivals = result['audio_times']
                    await pc.setLocalDescription(await pc.createAnswer())
                    ws.send({'type': 'answer', 'sdp': pc.localDescription.sdp})
                    # The server starts the audio and the text once the page plays.
                    asyncio.ensure_future(say_playing_when_open(ws, channel_open))
                elif m['type'] == 'ice' and m['candidate']:
                    await add_candidate(pc, m)
                elif m['type'] == 'error':
                    raise ConnectionError(m['message'])
                elif m['type'] == 'done':
                    result['sender'] = m
                    break
            # The last packets may come after the message: a moment for them.
            end = time.monotonic() + 2
            while result['last_seq'] != m['lastSequenceNumber'] and time.monotonic() < end:
                await asyncio.sleep(0.05)
            result['audio_packets'] = await audio_packets(pc)
    except Exception as e:  # noqa: BLE001 (reported per session)
        result['error'] = f'{type(e).__name__}: {e}'
    finally:
        await pc.close()
        ws.writer.close()
    return result


async def answer_offer(pc, ws, m):
    """Answers the server's offer `m`."""
    from aiortc import RTCSessionDescription
    await pc.setRemoteDescription(RTCSessionDescription(m['sdp'], 'offer'))
    await pc.setLocalDescription(await pc.createAnswer())
    ws.send({'type': 'answer', 'sdp': pc.localDescription.sdp})


async def add_candidate(pc, m):
    """Adds the server's ICE candidate `m` (an "ice" message with a candidate)."""
    from aiortc.sdp import candidate_from_sdp
    c = candidate_from_sdp(m['candidate'].split(':', 1)[1])
    c.sdpMLineIndex = m['sdpMLineIndex']
    c.sdpMid = str(m['sdpMLineIndex'])
    await pc.addIceCandidate(c)


async def playing_peer(port, first_packet, leave, until=(), again=None):
    """A peer that connects, answers the offer, says it plays once its data channel opens, and
    sets `first_packet` at its first PFAP packet. It leaves (closes its peer connection and
    WebSocket) when `leave` is set, returning 'left', or at the first message whose type is in
    `until`, returning that type. With `again`, it asks for that text each time the server
    starts one, so that the next always waits. Raises what the WebSocket raises when the server
    closes it."""
    from aiortc import RTCPeerConnection

    pc = RTCPeerConnection()
    ws = await WebSocket.connect(port)

    @pc.on('datachannel')
    def on_datachannel(channel):
        ws.send({'type': 'playing'})
        channel.on('message', lambda message: first_packet.set())

    try:
        while True:
            receiving = asyncio.ensure_future(ws.receive())
            leaving = asyncio.ensure_future(leave.wait())
            await asyncio.wait([receiving, leaving], return_when=asyncio.FIRST_COMPLETED)
            if not receiving.done():
                receiving.cancel()
                return 'left'
            leaving.cancel()
            m = receiving.result()
            if m['type'] == 'offer':
                await answer_offer(pc, ws, m)
            elif m['type'] == 'ice' and m['candidate']:
                await add_candidate(pc, m)
            elif m['type'] == 'saying' and again is not None:
                ws.send({'type': 'say', 'text': again})
            elif m['type'] in until:
                return m['type']
    finally:
        await pc.close()
        ws.writer.close()


async def audio_packets(pc):
    """The Opus RTP packets a peer connection has received (its receivers' stats)."""
    count = 0
    for receiver in pc.getReceivers():
        for stats in (await receiver.getStats()).values():
            if stats.type == 'inbound-rtp' and stats.kind == 'audio':
                count += stats.packetsReceived
    return count


async def say_playing_when_open(ws, channel_open):
    await channel_open.wait()
    ws.send({'type': 'playing'})


def whole(r):
    s = r['sender']
    return (r['error'] is None and s is not None and r['audio_packets'] > 0 and s['dropped'] == 0
            and r['packets'] == s['packets'] and r['last_seq'] == s['lastSequenceNumber']
            and r['state_equal'])


def decode_states(results):
    """Each session's FAP state from its packets, by web/src/'s receiver in node, compared with
    the settled values of the server's "done" message."""
    node = os.environ.get('NODE') or shutil.which('node')
    if node is None:
        raise SystemExit('no node: it decodes the PFAP packets (scripts/install-deps)')
    script = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'pfap_web_state.mjs')
    sessions = [[base64.b64encode(m).decode() for m in r['messages']] for r in results]
    decoded = subprocess.run([node, script], input=json.dumps(sessions), capture_output=True,
                             text=True, check=True)
    sys.stderr.write(decoded.stderr)
    for r, state in zip(results, json.loads(decoded.stdout)):
        s = r['sender']
        r['state_whole'] = state['stateWhole']
        r['state_equal'] = (s is not None and state['stateWhole']
                            and state['settled'] == s['settled'])
        r['state_differs'] = [i + 3 for i, (a, b) in enumerate(zip(state['settled'],
                                                                   (s or {}).get('settled', [])))
                              if a != b]


def lateness(times, clock_rate):
    """Each packet's arrival less its RTP time (in s; timestamps unwrapped), less the least of
    those: how much later than the stream's most punctual packet each came. A server that
    falls behind real time shows as lateness that grows."""
    if not times:
        return []
    offsets, ticks, last = [], 0, times[0][1]
    for arrival, ts in times:
        ticks += (ts - last + 2**31) % 2**32 - 2**31
        last = ts
        offsets.append(arrival - ticks / clock_rate)
    least = min(offsets)
    return [x - least for x in offsets]


def record_audio_arrivals():
    """Notes each Opus RTP packet's arrival and timestamp on its receiver's list (set by the
    session once it has the offer)."""
    from aiortc.rtcrtpreceiver import RTCRtpReceiver
    handle = RTCRtpReceiver._handle_rtp_packet

    async def noted(self, packet, arrival_time_ms):
        arrivals = getattr(self, 'pfap_arrivals', None)
        if arrivals is not None:
            arrivals.append((time.monotonic(), packet.timestamp))
        await handle(self, packet, arrival_time_ms)

    RTCRtpReceiver._handle_rtp_packet = noted


def late_summary(results, key, clock_rate):
    """The worst lateness over every session's packets, and the share of them late."""
    late = [x for r in results for x in lateness(r[key], clock_rate)]
    if not late:
        return 0.0, 0.0
    return max(late), sum(x > LATE_S for x in late) / len(late)


async def main():
    args = sys.argv[1:]
    row = '--row' in args
    by_thread = '--threads' in args
    args = [a for a in args if a not in ('--row', '--threads')]
    sessions = int(args[0]) if args else 4
    text = args[1] if len(args) > 1 else 'One, two, three.'
    server, port = start_server([f'--text={text}'])
    base = (len(os.listdir(f'/proc/{server.pid}/fd')), len(os.listdir(f'/proc/{server.pid}/task')))
    peak = list(base)
    rss_base = rss_kib(server.pid, 'VmRSS')
    thread_cpu = {}  # thread id: (name, CPU ticks), its last reading

    off_loopback = set()  # the server's sockets bound to another address than loopback's

    async def sample():
        for tick in range(1 << 62):
            peak[0] = max(peak[0], len(os.listdir(f'/proc/{server.pid}/fd')))
            peak[1] = max(peak[1], len(os.listdir(f'/proc/{server.pid}/task')))
            # A session's sockets live as long as it does: every 0.5 s finds them, and the
            # load generator shares the server's cores.
            if tick % 10 == 0:
                off_loopback.update(sockets_off_loopback(server.pid))
            if by_thread and tick % 10 == 0:
                for tid in os.listdir(f'/proc/{server.pid}/task'):
                    try:
                        stat = open(f'/proc/{server.pid}/task/{tid}/stat').read()
                    except OSError:
                        continue  # gone
                    name = stat[stat.index('(') + 1:stat.rindex(')')]
                    fields = stat.rsplit(')', 1)[1].split()
                    thread_cpu[tid] = (name, int(fields[11]) + int(fields[12]))
            await asyncio.sleep(0.05)

    # The server's own time and that of its children, live or waited for: pfaptts speaks each
    # sentence in a child of the server's pfap-espeak, which waits for them (docs/tts.md).
    def cpu_s():
        pids = [server.pid]
        for task in os.listdir(f'/proc/{server.pid}/task'):
            try:
                with open(f'/proc/{server.pid}/task/{task}/children') as children:
                    pids += [int(pid) for pid in children.read().split()]
            except FileNotFoundError:  # a thread that has ended
                pass
        ticks = 0
        for pid in pids:
            try:
                fields = open(f'/proc/{pid}/stat').read().rsplit(')', 1)[1].split()
            except FileNotFoundError:
                continue
            ticks += sum(int(f) for f in fields[11:15])
        return ticks / os.sysconf('SC_CLK_TCK')

    sampler = asyncio.ensure_future(sample())
    start = time.monotonic()
    cpu_start = cpu_s()
    results = await asyncio.gather(*(session(port, i + 1, 60) for i in range(sessions)))
    took = time.monotonic() - start
    cpu = cpu_s() - cpu_start
    rss_peak = rss_kib(server.pid, 'VmHWM')
    sampler.cancel()
    stopping = time.monotonic()
    server.terminate()
    out, err = server.communicate(timeout=120)
    stopped_in = time.monotonic() - stopping
    decode_states(results)
    audio_worst, audio_late = late_summary(results, 'audio_times', AUDIO_CLOCK_RATE)
    pfap_worst, pfap_late = late_summary(results, 'pfap_times', PFAP_CLOCK_RATE)
    good = sum(whole(r) for r in results)
    if by_thread:
        groups = {}
        for name, ticks in thread_cpu.values():
            key = re.sub(r'\d+', 'N', name)
            groups[key] = groups.get(key, 0) + ticks
        total = sum(groups.values()) or 1
        print('CPU by thread name (N: any number), sampled every 0.5 s:')
        for key, ticks in sorted(groups.items(), key=lambda kv: -kv[1]):
            print(f'  {key:18} {ticks / os.sysconf("SC_CLK_TCK"):6.2f} s  {ticks / total * 100:5.1f} %')
    if row:
        print(f'| {sessions} | {good} | {cpu / took / sessions * 100:.2f} % | '
              f'{(rss_peak - rss_base) / 1024 / sessions:.1f} MiB | '
              f'{(peak[0] - base[0]) / sessions:.1f} | {(peak[1] - base[1]) / sessions:.1f} | '
              f'{audio_worst * 1000:.0f} ms, {audio_late * 100:.1f} % | '
              f'{pfap_worst * 1000:.0f} ms, {pfap_late * 100:.1f} % |')
    for r in results:
        s = r['sender'] or {}
        if row and whole(r):
            continue
        print(f"session {r['session']}: {'whole' if whole(r) else 'NOT WHOLE'}: "
              f"{r['audio_packets']} Opus packets, {r['packets']} of {s.get('packets')} PFAP "
              f"packets, last sequence number {r['last_seq']} of {s.get('lastSequenceNumber')}, "
              + (f"FAP state equal to the sender's ({sum(v != 0 for v in s['settled'])} FAPs "
                 'not at rest)' if r['state_equal'] else
                 f"FAP state {'whole' if r['state_whole'] else 'not whole'}, differs from the "
                 f"sender's at FAPs {r['state_differs']}")
              + (f", {r['error']}" if r['error'] else ''))
    if not row:
        print(f'pfap-web: {base[0]} file descriptors and {base[1]} threads alone, at most '
              f'{peak[0]} and {peak[1]} with the sessions ({(peak[0] - base[0]) / sessions:.1f} '
              f'and {(peak[1] - base[1]) / sessions:.1f} per session); CPU {cpu:.2f} s in '
              f'{took:.1f} s ({cpu / took / sessions * 100:.1f} % of a core per session); RSS '
              f'{rss_base} KiB alone, peak {rss_peak} KiB '
              f'({(rss_peak - rss_base) / 1024 / sessions:.1f} MiB per session)')
        print(f'lateness against RTP time (lateness()): audio worst '
              f'{audio_worst * 1000:.0f} ms, {audio_late * 100:.1f} % of packets over '
              f'{LATE_S * 1000:.0f} ms; PFAP worst {pfap_worst * 1000:.0f} ms, '
              f'{pfap_late * 100:.1f} % over {LATE_S * 1000:.0f} ms')
        print(f'{good} of {sessions} sessions whole in {took:.1f} s; pfap-web exited '
              f'{server.returncode}, {stopped_in:.1f} s after SIGTERM')
    if off_loopback:
        print(f"pfap-web's sockets bound off loopback: {', '.join(sorted(off_loopback))}")
    if good != sessions or server.returncode != 0 or off_loopback:
        print(err[-2000:], file=sys.stderr)
        sys.exit(1)


def sockets_off_loopback(pid):
    """The local addresses (address:port) of pid's inet sockets bound to an address other than
    127.0.0.1 or ::1: pfap-web sends nothing off this machine (docs/web.md)."""
    inodes = set()
    for fd in os.listdir(f'/proc/{pid}/fd'):
        try:
            link = os.readlink(f'/proc/{pid}/fd/{fd}')
        except OSError:
            continue  # closed meanwhile
        if link.startswith('socket:['):
            inodes.add(link[8:-1])
    found = set()
    for table in ('udp', 'tcp', 'udp6', 'tcp6'):
        for line in open(f'/proc/{pid}/net/{table}').readlines()[1:]:
            fields = line.split()
            address, port = fields[1].split(':')
            if fields[9] in inodes and address not in ('0100007F', '0' * 24 + '01000000'):
                raw = bytes.fromhex(address)
                # /proc prints each 32-bit word of the address in host (little-endian) order.
                raw = b''.join(raw[i:i + 4][::-1] for i in range(0, len(raw), 4))
                found.add(f'{ipaddress.ip_address(raw)}:{int(port, 16)}')
    return found


def start_server(options, env=None):
    """pfap-web (PFAP_WEB) on a free port with these options; returns it and its port once it
    listens."""
    server = subprocess.Popen([os.environ['PFAP_WEB'], '--port=0', *options],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    line = ''
    while 'open http' not in line:
        line = server.stdout.readline()
        if not line:
            raise SystemExit(f'pfap-web did not start: {server.stderr.read()}')
    return server, int(re.search(r'127\.0\.0\.1:(\d+)/', line).group(1))


# gdb's bound in stacks() (a few seconds is usual), so that a test still says what it saw before
# meson's timeout.
STACKS_S = 30


def stacks(pid):
    """Where a server that does not exit is, by gdb if there is one, within STACKS_S."""
    if shutil.which('gdb'):
        try:
            subprocess.run(['gdb', '-p', str(pid), '-batch', '-ex', 'thread apply all bt'],
                           stdout=sys.stderr, stderr=subprocess.DEVNULL, timeout=STACKS_S)
        except subprocess.TimeoutExpired:
            print(f'gdb gave no stacks within {STACKS_S} s', file=sys.stderr)


def rss_kib(pid, field):
    """VmRSS (now) or VmHWM (peak) of a process, in KiB."""
    return int(open(f'/proc/{pid}/status').read().split(f'{field}:')[1].split()[0])


def skip_opus_decoding():
    """The audio is counted in RTP packets (the receiver's stats), not decoded: decoding would
    spend the CPU the load generator shares with the server it measures."""
    from aiortc.codecs import opus
    opus.OpusDecoder.decode = lambda self, frame: []


if __name__ == '__main__':
    enter_network_namespace()
    skip_opus_decoding()
    record_audio_arrivals()
    asyncio.run(main())
