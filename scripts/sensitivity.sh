#!/usr/bin/env bash
# The sensitivity study of docs/validation/sensitivity.md: GEM's modelling choices where the thesis
# is silent or was not followed (hull friction, vessel-floe elastic stress, breaking, thickness,
# 1 vs 3 DOF, a blunter bow, the impact window), one at a time from a base, on the 35 % resistance
# field and two load-study fields, three field seeds each. About a minute on 2 cores.
# Writes runs/sensitivity/, the tables of docs/validation/sensitivity.md and its sensitivity_*.svg.
# Usage: scripts/sensitivity.sh [BUILD_DIR] [JOBS]
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$here/build}"
jobs="${2:-2}"
[ -x "$build/gem" ] || "$here/scripts/setup.sh" "$build"
if ! command -v python3 >/dev/null; then  # the tables are written by a short Python script
  sudo_cmd=""; [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq && $sudo_cmd apt-get install -y -qq --no-install-recommends python3 >/dev/null
fi
work="$here/runs/sensitivity"
mkdir -p "$work"
for s in resistance_35 load_001_185 load_121_185 random_69_sizes; do
  "$build/gem" sweep "$here/scenarios/thesis/sensitivity/$s.toml" --out "$work/$s" --jobs "$jobs" --quiet
done
python3 "$here/scripts/sensitivity_tables.py" "$work" "$here/docs/validation" \
  "$(date -u +%Y-%m-%d), GEM $("$build/gem" info | head -1 | cut -d' ' -f2), commit $(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo unknown), CPU backend, $(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | xargs))"
