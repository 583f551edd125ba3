#!/bin/sh
# SPDX-License-Identifier: LGPL-2.1-or-later
# The browser test of tools/pfap-web (web/test/pfap-web.browser.js, docs/web.md), and the
# viseme detector's (web/test/viseme-detector.browser.js) and its benchmark: node, chromium
# and the server run inside a network namespace of their own with only lo up, so that
# WebRTC's ICE can only use 127.0.0.1 and no packet leaves the machine. unshare -n needs
# root: elsewhere the test is skipped (exit 77) saying so; CI runs as root.
# Arguments: node, the test file. PFAP_WEB names the server.
set -eu
if [ "$(id -u)" -ne 0 ]; then
  echo "SKIP: needs root: unshare -n makes the network namespace with only lo that WebRTC runs in (CI runs as root)"
  exit 77
fi
for tool in unshare ip timeout "${PFAP_CHROMIUM:-chromium}"; do
  if ! command -v "$tool" >/dev/null; then
    echo "SKIP: no $tool (scripts/install-deps installs util-linux, iproute2, coreutils, chromium)"
    exit 77
  fi
done
# The sanitizer build's runtimes are preloaded into every test process (tests/meson.build):
# not into node, sh or chromium, which are not ours; pfap-web links its own.
unset LD_PRELOAD
exec timeout 150 unshare -n sh -c 'ip link set lo up && exec "$0" --test "$1"' "$1" "$2"
