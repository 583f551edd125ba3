#!/bin/sh
# SPDX-License-Identifier: LGPL-2.1-or-later
# The browser test of the broadcast through Janus (web/test/janus-broadcast.browser.js,
# docs/web.md): node, janus, the sender and chromium run inside a network namespace of their
# own, so no packet leaves the machine. Besides lo it has a veth pair (10.28.0.1 and
# 10.28.0.2, both ends inside it), since Janus gathers no ICE candidate on a loopback
# interface; its ICE uses 10.28.0.1 (PFAP_JANUS_ICE_ADDRESS). unshare -n needs root: elsewhere
# the test is skipped (exit 77) saying so; CI runs as root. The veth ends get no IPv6
# link-local address and are up before chromium starts: an address that came later made
# chromium abort the pages' loads (net::ERR_NETWORK_CHANGED) in one sanitizer-build run.
# Arguments: node, the test file. PFAP_BROADCAST names the sender; PFAP_TIMEOUT (170 s)
# bounds the whole (the benchmark, web/bench/janus-viewers.browser.js, takes longer).
set -eu
if [ "$(id -u)" -ne 0 ]; then
  echo "SKIP: needs root: unshare -n makes the network namespace that Janus and WebRTC run in (CI runs as root)"
  exit 77
fi
for tool in unshare ip timeout janus "${PFAP_CHROMIUM:-chromium}"; do
  if ! command -v "$tool" >/dev/null; then
    echo "SKIP: no $tool (scripts/install-deps installs util-linux, iproute2, coreutils, janus, chromium)"
    exit 77
  fi
done
# The sanitizer build's runtimes are preloaded into every test process (tests/meson.build):
# not into node, sh, janus or chromium, which are not ours; pfap-broadcast links its own.
unset LD_PRELOAD
export PFAP_JANUS_ICE_ADDRESS=10.28.0.1
exec timeout "${PFAP_TIMEOUT:-170}" unshare -n sh -c '
  ip link set lo up &&
  ip link add pfap0 type veth peer name pfap1 &&
  ip link set pfap0 addrgenmode none && ip link set pfap1 addrgenmode none &&
  ip addr add 10.28.0.1/24 dev pfap0 && ip addr add 10.28.0.2/24 dev pfap1 &&
  ip link set pfap0 up && ip link set pfap1 up &&
  for i in $(seq 50); do
    ip link show pfap0 | grep -q "state UP" && ip link show pfap1 | grep -q "state UP" && break
    sleep 0.1
  done &&
  exec "$0" --test "$1"' "$1" "$2"
