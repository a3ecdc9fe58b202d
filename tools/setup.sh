#!/usr/bin/env bash
# One-time set-up on a fresh Debian/Ubuntu machine: system packages, then .venv.
# Idempotent: a second run only checks.  Used by `make demo`, `make test` and .ci/run.
set -euo pipefail
cd "$(dirname "$0")/.."

APT_PACKAGES=(
  libegl1 libgl1 libegl-mesa0 libgl1-mesa-dri  # OpenGL through EGL (Mesa llvmpipe without a GPU)
  xvfb xauth                                   # a real window in tests and on servers
  libx11-6 libxtst6                            # the window tests read the X screen and type keys (XTest)
  fluidsynth fluid-soundfont-gm                # MIDI -> audio for videos with sound
  jackd2                                       # live MIDI ports (jam) through JACK
  chromium                                     # the browser viewer's tests (Playwright drives it)
)

missing=()
for p in "${APT_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "setup: installing system packages: ${missing[*]}"
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

PY=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  echo "setup: creating .venv"
  "$PY" -m venv .venv
fi
stamp=.venv/.virja-installed
if [ ! -f "$stamp" ] || [ pyproject.toml -nt "$stamp" ]; then
  echo "setup: installing virja, its test tools and the Ray extra into .venv"
  .venv/bin/python -m pip install -q --upgrade pip >/dev/null
  .venv/bin/python -m pip install -q -e '.[test,ray]'
  touch "$stamp"
fi
# The planner's inner loops compiled in place (virja/plan/_dpcore.c, with gcc and the
# Python headers; without them the planner runs its Python loops, which plan the same).
.venv/bin/python tools/build_dpcore.py || echo "setup: the planner's C loops were not built (it runs its Python loops)"

# Node tools the tests run (tools/node/package.json, pinned by its package-lock.json):
# the Khronos glTF Validator checks `virja export --gltf` output; node-rtpmidi (npm
# "rtpmidi") is the independent RTP-MIDI peer.  `npm install --omit=optional`, not
# `npm ci`: rtpmidi names optional native mDNS modules (one a git dependency) that the
# lock cannot hold, so `npm ci` refuses it as out of sync; install keeps the lock as is.
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "setup: installing nodejs and npm"
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends nodejs npm >/dev/null
fi
node_stamp=tools/node/node_modules/.virja-installed
if [ ! -f "$node_stamp" ] || [ tools/node/package-lock.json -nt "$node_stamp" ]; then
  echo "setup: installing the node test tools into tools/node/node_modules"
  (cd tools/node && npm install --omit=optional --no-audit --no-fund --loglevel=error >/dev/null)
  touch "$node_stamp"
fi
