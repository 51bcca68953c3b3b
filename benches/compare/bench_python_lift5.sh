#!/usr/bin/env bash
# Same-process comparison from Python (see benches/compare/bench_python_lift5.py): lift5 variants
# made by mjcf_forge against robosuite's own classes, and the cost of crossing into Python.
# Installs the package (a release abi3 wheel built by maturin from this checkout) into
# robosuite's light venv (scripts/setup_robosuite.sh), then runs the comparison there.
# Arguments go to the Python script (--rounds R --forge N --robosuite M).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
bash scripts/setup_robosuite.sh >/dev/null
rm -rf target/wheels/bench
PATH="$PWD/.cache/venv/bin:$PATH" maturin build --release --quiet --out target/wheels/bench >/dev/null
.cache/venv-robosuite/bin/python -m pip install --quiet --disable-pip-version-check \
  --force-reinstall --no-deps target/wheels/bench/mjcf_forge-*.whl
exec .cache/venv-robosuite/bin/python benches/compare/bench_python_lift5.py "$@"
