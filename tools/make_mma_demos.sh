#!/usr/bin/env bash
# Regenerate the MMA demo sessions in virja/demo/ from tools/demos/*.mma.
# MMA (Musical MIDI Accompaniment, Debian package `mma`) writes a type-1 MIDI
# file per song: a drum track on channel 10, a bass track, and chords the band
# does not play.  The MIDI files are committed, so MMA is needed only to change them.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v mma >/dev/null || { echo "make_mma_demos: needs mma (apt-get install mma)" >&2; exit 1; }
for src in tools/demos/*.mma; do
  name=$(basename "$src" .mma)
  mma "$src" -f "virja/demo/$name.mid" | grep -v "PLUGIN" || true
done
