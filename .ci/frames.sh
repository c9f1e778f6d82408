#!/usr/bin/env bash
# frames.sh BIN OUTDIR [extra render flags...]: renders a reference set of 94 frames (PFM and
# text: every stage, the built-in scenes, anti-aliased, path-traced raw/denoised/independent,
# 1 and 2 threads) with the raytty binary BIN. Not run by CI: a maintainer's check that a
# change keeps every frame byte for byte. Render a set with the old binary and with the new
# one (and with `--simd portable|sse2|avx2|avx512`), then `diff -r -q OLD NEW`.
set -euo pipefail
bin=$1; out=$2; shift 2
mkdir -p "$out"
EXTRA=("$@")
for th in 1 2; do
  for scene in cornell mirror lights; do
    for stage in flat light direct shadows indirect; do
      RAYON_NUM_THREADS=$th "$bin" render --scene $scene --stage $stage --pixels 101x61 "${EXTRA[@]}" --format pfm -o "$out/$scene-$stage-t$th.pfm"
      RAYON_NUM_THREADS=$th "$bin" render --scene $scene --stage $stage --pixels 67x45 --samples 3 "${EXTRA[@]}" --format pfm -o "$out/$scene-$stage-aa3-t$th.pfm"
    done
    RAYON_NUM_THREADS=$th "$bin" render --scene $scene --stage gi --pixels 64x40 --samples 4 "${EXTRA[@]}" --format pfm -o "$out/$scene-gi4-t$th.pfm"
    RAYON_NUM_THREADS=$th "$bin" render --scene $scene --stage gi --pixels 64x40 --samples 5 --denoise off "${EXTRA[@]}" --format pfm -o "$out/$scene-gi5raw-t$th.pfm"
    RAYON_NUM_THREADS=$th "$bin" render --scene $scene --stage gi --pixels 48x30 --samples 2 --sampler independent "${EXTRA[@]}" --format pfm -o "$out/$scene-gi2ind-t$th.pfm"
    RAYON_NUM_THREADS=$th "$bin" render --scene $scene --stage indirect --pixels 80x50 --camera 0.3,-0.2,-2.5,20 --light 0.2,0.3,-0.4 "${EXTRA[@]}" --format pfm -o "$out/$scene-pose-t$th.pfm"
  done
  RAYON_NUM_THREADS=$th "$bin" render --scene sphere --stage indirect --pixels 120x80 "${EXTRA[@]}" --format pfm -o "$out/sphere-indirect-t$th.pfm"
  RAYON_NUM_THREADS=$th "$bin" render --scene sphere --stage shadows --pixels 60x40 --samples 2 "${EXTRA[@]}" --format pfm -o "$out/sphere-aa2-t$th.pfm"
  RAYON_NUM_THREADS=$th "$bin" render --scene sphere --stage gi --pixels 40x30 --samples 2 "${EXTRA[@]}" --format pfm -o "$out/sphere-gi2-t$th.pfm"
  RAYON_NUM_THREADS=$th "$bin" render --scene cornell --stage indirect --size 80x24 "${EXTRA[@]}" --format ansi -o "$out/cornell-ansi-t$th.txt"
  RAYON_NUM_THREADS=$th "$bin" render --scene lights --stage gi --size 60x20 --samples 4 "${EXTRA[@]}" --format ansi256 -o "$out/lights-ansi256-t$th.txt"
done
echo "$(ls "$out" | wc -l) frames in $out"
