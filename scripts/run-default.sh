#!/usr/bin/env bash
# Installs what is missing, builds GEM and runs the default scenario: the thesis's 35 % random
# field (560 floes) with the vessel at 370 kN bollard thrust. Extra arguments go to `gem run`.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$here/scripts/setup.sh" "$here/build" gem  # the gem command only: the tests are test.sh's
exec "$here/build/gem" run "$here/scenarios/thesis/random_35.toml" --out "$here/runs/random_35" "$@"
