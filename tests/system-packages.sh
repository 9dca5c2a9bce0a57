#!/bin/sh
# The Debian packages the test suite needs besides Python's: headless Chromium (tests/test_render.py loads
# the HTML replay in it) and Graphviz's dot (mrgc graph writes .svg/.png through it).  The README's test
# command and .ci/run both call this script, so a fresh machine sets itself up; on a machine that has both
# it does nothing.  apt-get runs as root, or through sudo when that needs no password; otherwise the script
# says what to install and exits 1 (the tests would fail without them, never skip).
set -eu
missing=""
if ! command -v chromium >/dev/null 2>&1 && ! command -v chromium-browser >/dev/null 2>&1 \
    && ! command -v google-chrome >/dev/null 2>&1; then
  missing=" chromium"
fi
if ! command -v dot >/dev/null 2>&1; then
  missing="$missing graphviz"
fi
[ -z "$missing" ] && exit 0
if [ "$(id -u)" = 0 ]; then
  run=""
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
  run="sudo -n"
else
  echo "tests/system-packages.sh: the tests need the Debian packages:$missing; install them as root:" \
    "apt-get install -y$missing" >&2
  exit 1
fi
echo "tests/system-packages.sh: installing$missing (apt-get)" >&2
$run apt-get update -qq
# shellcheck disable=SC2086
DEBIAN_FRONTEND=noninteractive $run apt-get install -y -qq $missing >/dev/null
