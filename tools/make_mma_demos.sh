#!/usr/bin/env bash
# Regenerate the MMA demo sessions in virja/demo/ from tools/demos/*.mma.
# MMA (Musical MIDI Accompaniment, Debian package `mma`) writes a type-1 MIDI
# file per song: a drum track on channel 10, a bass track, chords the band does
# not play, and the chord symbols as lyrics (for the heads-up display).  RndSeed
# makes its humanising repeatable.  The MIDI files are committed, so MMA is
# needed only to change them.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v mma >/dev/null || { echo "make_mma_demos: needs mma (apt-get install mma)" >&2; exit 1; }
for src in tools/demos/*.mma; do
  name=$(basename "$src" .mma)
  log=$(mma "$src" -f "virja/demo/$name.mid" 2>&1) || { echo "$log" >&2; exit 1; }
  if grep -q "^Error" <<<"$log"; then echo "$log" >&2; exit 1; fi
  grep -v "PLUGIN" <<<"$log" || true
done
