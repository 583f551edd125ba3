#!/usr/bin/env python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""tools/pfap-web against hostile clients (docs/security.md, "pfap-web"): wrongly typed and
malformed signalling messages, pages of another origin, more sessions than the server takes
and sessions that never answer the offer. Each is refused with a clear message, and the
server and its other sessions go on.

The clients are plain sockets speaking just enough WebSocket (RFC 6455): the test needs
headers a browser would not let a page set (Origin) and messages no page would send. The
server's sessions run webrtcbin, so the test runs in a network namespace of its own with only
lo (unshare -n, as root; elsewhere it is skipped). PFAP_WEB names the server."""
import base64
import json
import os
import resource
import select
import shutil
import socket
import struct
import subprocess
import sys
import time
import unittest

WEB_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'web')


def enter_network_namespace():
    """Runs this script again inside a network namespace with only lo, or skips (77)."""
    if os.environ.get('PFAP_WEB_NETNS') == '1':
        return
    if os.geteuid() != 0:
        print('SKIP: needs root: unshare -n makes the network namespace with only lo that '
              "pfap-web's WebRTC sessions run in (CI runs as root)")
        sys.exit(77)
    for tool in ('unshare', 'ip'):
        if shutil.which(tool) is None:
            print(f'SKIP: no {tool} (scripts/install-deps installs util-linux, iproute2)')
            sys.exit(77)
    os.environ['PFAP_WEB_NETNS'] = '1'
    os.execvp('unshare', ['unshare', '-n', 'sh', '-c', 'ip link set lo up && exec "$0" "$@"',
                          sys.executable, *sys.argv])


class Closed(Exception):
    """The server closed the WebSocket: code and reason."""

    def __init__(self, code, reason):
        super().__init__(f'closed {code} {reason}')
        self.code = code
        self.reason = reason


class WebSocket:
    """A WebSocket client on a plain socket: text messages out (masked), frames in."""

    def __init__(self, port, origin=None, path='/ws'):
        self.sock = socket.create_connection(('127.0.0.1', port), timeout=10)
        key = base64.b64encode(os.urandom(16)).decode()
        request = (f'GET {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\n'
                   f'Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n'
                   'Sec-WebSocket-Version: 13\r\n')
        if origin is not None:
            request += f'Origin: {origin}\r\n'
        self.sock.sendall((request + '\r\n').encode())
        head = b''
        while b'\r\n\r\n' not in head:
            chunk = self.sock.recv(4096)
            if not chunk:
                break
            head += chunk
        head, _, self.buffer = head.partition(b'\r\n\r\n')
        self.status = int(head.split(b' ')[1]) if head else 0

    def send(self, message, opcode=1):
        data = message.encode() if isinstance(message, str) else message
        mask = os.urandom(4)
        header = bytes([0x80 | opcode])
        if len(data) < 126:
            header += bytes([0x80 | len(data)])
        elif len(data) < 65536:
            header += bytes([0x80 | 126]) + struct.pack('!H', len(data))
        else:
            header += bytes([0x80 | 127]) + struct.pack('!Q', len(data))
        masked = bytes(b ^ mask[i % 4] for i, b in enumerate(data))
        self.sock.sendall(header + mask + masked)

    def _read(self, n):
        while len(self.buffer) < n:
            chunk = self.sock.recv(65536)
            if not chunk:
                raise Closed(1006, 'connection lost')
            self.buffer += chunk
        out, self.buffer = self.buffer[:n], self.buffer[n:]
        return out

    def receive(self):
        """The next text message, parsed; raises Closed at a close frame."""
        while True:
            first, second = self._read(2)
            size = second & 0x7f
            if size == 126:
                size = struct.unpack('!H', self._read(2))[0]
            elif size == 127:
                size = struct.unpack('!Q', self._read(8))[0]
            payload = self._read(size)
            opcode = first & 0x0f
            if opcode == 8:
                code = struct.unpack('!H', payload[:2])[0] if len(payload) >= 2 else 1005
                raise Closed(code, payload[2:].decode(errors='replace'))
            if opcode == 1:
                return json.loads(payload)

    def receive_until(self, kind):
        while True:
            m = self.receive()
            if m['type'] == kind:
                return m

    def refusal(self):
        """The error message before the close, and the close code."""
        error = None
        try:
            while True:
                m = self.receive()
                if m['type'] == 'error':
                    error = m['message']
        except Closed as closed:
            return error, closed.code

    def close(self):
        self.sock.close()


class Server:
    def __init__(self, *args, nofile=None):
        def limit():
            if nofile is not None:
                resource.setrlimit(resource.RLIMIT_NOFILE, (nofile, nofile))

        self.process = subprocess.Popen(
            [os.environ['PFAP_WEB'], '--port=0', f'--web-dir={WEB_DIR}', *args],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, preexec_fn=limit)
        self.out = b''
        deadline = time.monotonic() + 20
        while b'open http://127.0.0.1:' not in self.out:
            if time.monotonic() > deadline or self.process.poll() is not None:
                raise AssertionError(f'pfap-web did not start: {self.stop()}')
            ready, _, _ = select.select([self.process.stdout], [], [], 1)
            if ready:
                self.out += os.read(self.process.stdout.fileno(), 4096)
        line = self.out.split(b'open http://127.0.0.1:')[1]
        self.port = int(line.split(b'/')[0])

    def alive(self):
        return self.process.poll() is None

    def stop(self):
        """Stops it as Ctrl-C would; its exit status, standard output and error."""
        if self.process.poll() is None:
            self.process.terminate()
        try:
            out, err = self.process.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            self.process.kill()
            out, err = self.process.communicate()
        return self.process.returncode, (self.out + out).decode(errors='replace'), \
            err.decode(errors='replace')

    def session(self, origin=None):
        ws = WebSocket(self.port, origin=origin)
        assert ws.status == 101, f'status {ws.status}'
        ws.receive_until('timing')
        return ws


def still_serves(test, server, ws):
    """`ws`'s session still answers: a request for a complete state gets the sender's state."""
    ws.send('{"type": "complete"}')
    test.assertEqual(len(ws.receive_until('state')['settled']), 72)
    test.assertTrue(server.alive())


# Each member the server reads, given every JSON type it must not have; today's server
# crashed on 8 of them (a number or a boolean where it wanted a string).
WRONG_VALUES = {'number': 5, 'boolean': True, 'null': None, 'object': {'a': 1}, 'array': ['x']}
WRONGLY_TYPED = (
    [{'type': v} for v in WRONG_VALUES.values()]
    + [{'type': 'say', 'text': v} for v in WRONG_VALUES.values()]
    + [{'type': 'answer', 'sdp': v} for v in WRONG_VALUES.values()]
    + [{'type': 'ice', 'candidate': v, 'sdpMLineIndex': 0} for v in WRONG_VALUES.values()]
    + [{'type': 'ice', 'candidate': 'candidate:1 1 udp 1 127.0.0.1 9 typ host',
        'sdpMLineIndex': v} for v in ('0', True, {'a': 1}, [0], 1.5, -1, 1 << 40)]
)
MALFORMED = [
    '[' * 131072,  # json-glib parses nesting by recursion: this overflowed the stack
    '[' * 60000,
    'not JSON', '[]', '"answer"', '{"type": "dance"}', '{"type": "say"}', '{"type": "answer"}',
    '{"type": "answer", "sdp": ""}', '{"type": "answer", "sdp": "not an SDP"}',
    json.dumps({'type': 'say', 'text': 'x' * 5000}),
]


class Hostile(unittest.TestCase):
    def test_wrongly_typed_and_malformed_messages_close_only_their_session(self):
        server = Server('--text=Hi.')
        try:
            bystander = server.session()
            sent = 0
            for message in [json.dumps(m) for m in WRONGLY_TYPED] + MALFORMED:
                with self.subTest(message=message[:80]):
                    ws = server.session()
                    ws.send(message)
                    sent += 1
                    error, code = ws.refusal()
                    ws.close()
                    self.assertTrue(server.alive(), 'pfap-web died')
                    self.assertIsNotNone(error)
                    self.assertIn('bad message', error)
                    self.assertEqual(code, 1008)
            # A binary message is not signalling either.
            ws = server.session()
            ws.send(b'\x00\x01', opcode=2)
            self.assertEqual(ws.refusal(), ('a binary message', 1003))
            still_serves(self, server, bystander)
            # A good message still works in a new session.
            ws = server.session()
            ws.send('{"type": "say", "text": "Hello."}')
            still_serves(self, server, ws)
        finally:
            status, out, err = server.stop()
        self.assertEqual(status, 0, err)
        # One warning per bad message would be sent + 1 lines; rate-limited, log2 of it.
        warnings = [line for line in err.splitlines() if 'bad message' in line or 'binary' in line]
        self.assertLessEqual(len(warnings), 8, err)
        self.assertIn('(1 of this kind so far)', err)
        self.assertIn('(32 of this kind so far)', err)

    def test_origin(self):
        server = Server('--allow-origin=http://example.org:8000')
        try:
            for origin in ('http://evil.example', f'http://127.0.0.1:{server.port + 1}',
                           'null', f'https://127.0.0.1:{server.port}'):
                with self.subTest(origin=origin):
                    ws = WebSocket(server.port, origin=origin)
                    self.assertEqual(ws.status, 403)
                    ws.close()
            for origin in (f'http://127.0.0.1:{server.port}', f'http://localhost:{server.port}',
                           'http://example.org:8000', None):
                with self.subTest(origin=origin):
                    server.session(origin=origin).close()
            self.assertTrue(server.alive())
        finally:
            status, out, err = server.stop()
        self.assertEqual(status, 0, err)
        self.assertIn('a page of another origin', err)

    def test_sessions_past_the_cap_are_refused(self):
        server = Server('--max-sessions=2')
        try:
            first, second = server.session(), server.session()
            extra = WebSocket(server.port)
            error, code = extra.refusal()
            self.assertEqual(code, 1008)
            self.assertIn('the server is full: 2 sessions', error)
            still_serves(self, server, second)
            first.close()  # one goes: room for another
            time.sleep(0.5)
            still_serves(self, server, server.session())
        finally:
            status, out, err = server.stop()
        self.assertEqual(status, 0, err)
        self.assertIn('at most 2 sessions at once', out)

    def test_the_cap_follows_the_open_file_limit(self):
        # Room for 3 sessions beside the reserve: the 4th and later are refused, and the
        # server, which aborted when the descriptors ran out, goes on.
        per_session, reserve = 25, 64  # kFdsPerSession, kReservedFds
        server = Server(nofile=reserve + 3 * per_session + per_session // 2)
        try:
            self.assertIn(b'at most 3 sessions at once', server.out)
            held = [server.session() for _ in range(3)]
            for _ in range(5):
                error, code = WebSocket(server.port).refusal()
                self.assertEqual(code, 1008)
                self.assertIn('the server is full', error)
            for ws in held:
                still_serves(self, server, ws)
        finally:
            status, out, err = server.stop()
        self.assertEqual(status, 0, err)

    def test_a_session_that_never_answers_is_closed(self):
        server = Server('--connect-timeout=1')
        try:
            ws = server.session()
            start = time.monotonic()
            error, code = ws.refusal()
            self.assertLess(time.monotonic() - start, 5)
            self.assertEqual(code, 1008)
            self.assertIn('no answer to the offer in 1 s', error)
            self.assertTrue(server.alive())
        finally:
            status, out, err = server.stop()
        self.assertEqual(status, 0, err)


if __name__ == '__main__':
    enter_network_namespace()
    unittest.main()
