# SPDX-License-Identifier: LGPL-2.1-or-later
"""The example programs in examples/python and examples/gjs, run as a user runs them, against
the build tree (tests/python/meson.build sets the paths)."""
import contextlib
import os
import re
import shlex
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import gi

gi.require_version("Gst", "1.0")
gi.require_version("GstPfap", "1.0")
from gi.repository import Gst, GstPfap  # noqa: E402

import pytest  # noqa: E402

Gst.init(None)

SOURCE = Path(__file__).resolve().parents[2]
HELLO = SOURCE / "docs" / "examples" / "hello.pfap"
PYTHON_RECEIVER = [str(SOURCE / "examples" / "python" / "pfap-receiver.py")]
GJS_RECEIVER = ["gjs", str(SOURCE / "examples" / "gjs" / "pfap-receiver.js")]
MOUTH = [str(SOURCE / "examples" / "python" / "pfap-mouth.py")]
needs_gjs = pytest.mark.skipif(shutil.which("gjs") is None, reason="gjs is not installed")


def phoneme_names(path):
    """The phonemes of a .pfap file, read with pfaptextparse and named with GstPfap."""
    pipeline = Gst.parse_launch("filesrc name=src ! pfaptextparse ! appsink name=sink sync=false")
    pipeline.get_by_name("src").set_property("location", str(path))
    sink = pipeline.get_by_name("sink")
    pipeline.set_state(Gst.State.PLAYING)
    arpabet = GstPfap.Alphabet.find(GstPfap.ALPHABET_ARPABET)
    names = []
    while (sample := sink.try_pull_sample(5 * Gst.SECOND)) is not None:
        event = GstPfap.Event.new_from_buffer(sample.get_buffer())
        if event.get_kind() == GstPfap.EventKind.PHONEME:
            names.append(arpabet.get_phoneme_name(event.get_symbol()))
    pipeline.set_state(Gst.State.NULL)
    return names


def free_udp_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def receive(command):
    """Runs a receiver example on a free port, sends hello.pfap to it, returns its output."""
    port = free_udp_port()
    receiver = subprocess.Popen(command + ["--port", str(port), "--idle-exit", "2"],
                                stdout=subprocess.PIPE, text=True)
    try:
        assert receiver.stdout.readline().startswith("listening on 127.0.0.1:%d" % port)
        sender = Gst.parse_launch(
            "filesrc name=src ! pfaptextparse alphabet=" + GstPfap.ALPHABET_ARPABET +
            " ! rtppfappay ! udpsink host=127.0.0.1 port=%d" % port)
        sender.get_by_name("src").set_property("location", str(HELLO))
        sender.set_state(Gst.State.PLAYING)
        message = sender.get_bus().timed_pop_filtered(
            20 * Gst.SECOND, Gst.MessageType.EOS | Gst.MessageType.ERROR)
        sender.set_state(Gst.State.NULL)
        assert message is not None and message.type == Gst.MessageType.EOS
        out, _ = receiver.communicate(timeout=30)
    finally:
        receiver.kill()
        receiver.wait()
    assert receiver.returncode == 0
    return out


@pytest.mark.parametrize("command", [
    PYTHON_RECEIVER, MOUTH, pytest.param(GJS_RECEIVER, marks=needs_gjs)],
    ids=["python-receiver", "python-mouth", "gjs-receiver"])
def test_examples_answer_help(command):
    run = subprocess.run(command + ["--help"], capture_output=True, text=True, timeout=30)
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith("usage: ")


@pytest.mark.parametrize("command", [PYTHON_RECEIVER, pytest.param(GJS_RECEIVER, marks=needs_gjs)],
                         ids=["python", "gjs"])
def test_receiver_prints_every_phoneme_by_name(command):
    expected = phoneme_names(HELLO)
    assert len(expected) > 5
    out = receive(command)
    got = [line.split()[2] for line in out.splitlines() if " phoneme " in line]
    assert got == expected
    assert "    FAP 69 -> 30 over 400 ms" in out  # hello.pfap's first bookmark


def apps_md_receiver_block():
    """docs/apps.md's shell block for the receivers: the receiver commands (the Python one, and
    the gjs one in its comment) and the sender's gst-launch-1.0 command, each as words."""
    (block,) = [b for b in apps_md_blocks("sh") if "pfap-receiver" in b]
    lines = block.replace("\\\n", " ").splitlines()
    documented = r"(examples/\S+ --port 5004) &"
    receivers = [shlex.split(command) for line in lines for command in re.findall(documented, line)]
    (sender,) = [shlex.split(line) for line in lines if line.startswith("gst-launch-1.0 ")]
    return receivers, sender


def with_port(words, port):
    return [w.replace("5004", str(port)) for w in words]


@contextlib.contextmanager
def documented_receiver(interpreter):
    """The documented receiver command run in `interpreter`'s language, as the block has it:
    from the source tree, the script as the program. Gives (process, port); kills it if a test
    left it running."""
    receivers, _ = apps_md_receiver_block()
    (command,) = [r for r in receivers if r[0].startswith("examples/%s/" % interpreter)]
    port = free_udp_port()
    receiver = subprocess.Popen(with_port(command, port), cwd=SOURCE, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
    try:
        assert receiver.stdout.readline().startswith("listening on 127.0.0.1:%d" % port)
        yield receiver, port
    finally:
        if receiver.poll() is None:
            receiver.kill()
            receiver.communicate()


def stop_with(receiver, signum):
    """Sends `signum`; the receiver must end within 5 s, with status 0 and nothing on stderr.
    Returns what else it printed."""
    receiver.send_signal(signum)
    try:
        out, err = receiver.communicate(timeout=5)
    except subprocess.TimeoutExpired:
        pytest.fail("still running 5 s after signal %d" % signum)
    assert receiver.returncode == 0, err
    assert err == ""
    return out


def test_apps_md_shows_both_receivers():
    receivers, sender = apps_md_receiver_block()
    assert [r[0] for r in receivers] == ["examples/python/pfap-receiver.py",
                                         "examples/gjs/pfap-receiver.js"]
    assert sender[0] == "gst-launch-1.0"


# The documented block as a user runs it, with no --idle-exit: the receiver prints every phoneme
# the documented sender sends, and Ctrl-C then ends it with status 0 and nothing on stderr.
@pytest.mark.parametrize("interpreter", ["python", pytest.param("gjs", marks=needs_gjs)])
def test_documented_receiver_prints_the_session_and_ends_on_ctrl_c(interpreter):
    expected = phoneme_names(HELLO)
    with documented_receiver(interpreter) as (receiver, port):
        _, sender = apps_md_receiver_block()
        sent = subprocess.run(with_port(sender, port), cwd=SOURCE, capture_output=True,
                              text=True, timeout=30)
        assert sent.returncode == 0, sent.stderr
        time.sleep(1)  # what was sent is printed
        out = stop_with(receiver, signal.SIGINT)
    got = [line.split()[2] for line in out.splitlines() if " phoneme " in line]
    assert got == expected


# Ctrl-C (SIGINT) or kill (SIGTERM) while nothing comes: the receiver ends at once, status 0.
@pytest.mark.parametrize("interpreter", ["python", pytest.param("gjs", marks=needs_gjs)])
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_documented_receiver_ends_on_a_signal_while_idle(interpreter, signum):
    with documented_receiver(interpreter) as (receiver, _):
        time.sleep(0.5)
        assert stop_with(receiver, signum) == ""


def test_mouth_opens_and_closes_with_the_jaw():
    run = subprocess.run(MOUTH + ["--plain", str(HELLO)], capture_output=True, text=True,
                         timeout=60)
    assert run.returncode == 0, run.stderr
    # A frame is the top lip, one row per step of the opening, then the bottom lip.
    frames, rows = [], 0
    for line in run.stdout.splitlines():
        if line.startswith(" _"):
            rows = 0
        elif line.startswith("|"):
            rows += 1
        else:
            frames.append(rows)
    assert len(frames) > 25, "fewer frames than a second at 25 per second"
    assert max(frames) >= 2, "the mouth never opened"
    assert frames[-1] == 0, "the mouth is still open after the last phoneme"


def apps_md_blocks(language):
    text = (SOURCE / "docs" / "apps.md").read_text()
    return re.findall(r"^```%s\n(.*?)^```$" % re.escape(language), text, re.M | re.S)


def test_apps_md_python_runs():
    (code,) = apps_md_blocks("python")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=30)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    assert lines[0] == "AA <enum GST_PFAP_VISEME_A of type GstPfap.Viseme>"
    assert lines[1] == "[(69, 40, 500)]"
    assert lines[2].split() == ["20.0", "40"]  # halfway along the spline, then its target
    assert lines[3] == "at byte 11: transition time out of range"


@pytest.mark.parametrize("language, compiler", [("c", "cc"), ("cpp", "c++")])
def test_apps_md_c_and_cpp_compile(language, compiler):
    if shutil.which(compiler) is None or shutil.which("pkg-config") is None:
        pytest.skip("no %s or pkg-config" % compiler)
    (code,) = apps_md_blocks(language)
    flags = subprocess.run(["pkg-config", "--cflags", "gstreamer-pfap-1.0", "gstreamer-app-1.0"],
                           capture_output=True, text=True, check=True).stdout.split()
    std = ["-std=c++20"] if language == "cpp" else []
    run = subprocess.run([compiler, "-x", "c++" if language == "cpp" else "c", "-c", "-o",
                          os.devnull, "-", "-Wall", "-Werror", "-Wno-unused-function",
                          "-Wno-unused-variable"] + std + flags,
                         input=code, capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
