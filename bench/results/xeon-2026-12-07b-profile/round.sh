#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-07 (session 28): the session's builds against main before it (s39,
# 75a2694) and 4e89f89 (old) on the lent machine's Xeon: the 824-floe field on one pinned core in
# ROUNDS alternated rounds, then 10^5 floes at THREADS, with the pool's account
# (../xeon-2026-12-06f-pool/diagnose.sh does both). Run from the repository root with
# .gpu-stage-cpu carried; writes under $OUT.
R=$PWD; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
D="$R/bench/results/xeon-2026-12-06f-pool/diagnose.sh"
BUILDS=${BUILDS:-"s39 s40"}
BUILDS="$BUILDS" THREADS="" ROUNDS_824=${ROUNDS:-20} OUT=$OUT/rounds bash "$D"
BUILDS="$BUILDS" THREADS="${THREADS:-1 2 16}" ROUNDS_824=0 OUT=$OUT/scaling bash "$D"
