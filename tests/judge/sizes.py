#!/usr/bin/env python3
"""Print the sizes of MuJoCo models as `mjcf-forge compile --json` prints them.

Usage:
  sizes.py MODEL.xml...          sizes of each model
  sizes.py --list FILE           sizes of each model named in FILE (one path a line)

Compiles every model with mujoco.MjModel.from_xml_path, all in this one process, and
prints one JSON line per model, in input order:
  {"path": "<as given>", "nbody": 2, "njnt": 1, ...}
or, when MuJoCo refuses the model,
  {"path": "<as given>", "error": "<MuJoCo's message>"}
The size keys and their order are those of `mjcf_forge::mujoco::Sizes::to_json`; a key
this MuJoCo's MjModel lacks is left out. Exits 0 even when models fail (the caller
compares); 2 on bad usage.

Run it with the setup's venv: .cache/venv/bin/python tests/judge/sizes.py ...
"""
from __future__ import annotations

import json
import sys

# Same order as the Rust `Sizes` (src/mujoco/model.rs): the required nine first.
KEYS = [
    "nbody", "njnt", "ngeom", "nsite", "nu", "nsensor", "nq", "nv", "nmesh",
    "na", "nactuator", "ncam", "nlight", "ntex", "nmat", "ntendon", "nwrap", "neq",
    "nkey", "nmocap", "nhfield", "nskin", "nflex", "npair", "nexclude", "nnumeric",
    "ntext", "ntuple", "nplugin", "nsensordata", "nuser_body", "nuser_jnt",
    "nuser_geom", "nuser_site", "nuser_cam", "nuser_tendon", "nuser_actuator",
    "nuser_sensor", "nnames",
]


def sizes(mujoco, path: str) -> dict:
    try:
        model = mujoco.MjModel.from_xml_path(path)
    except Exception as e:  # MuJoCo raises ValueError; report anything as the model's error
        return {"path": path, "error": str(e).strip()}
    out = {"path": path}
    for key in KEYS:
        if hasattr(model, key):
            out[key] = int(getattr(model, key))
    return out


def main(argv: list[str]) -> int:
    if argv[:1] == ["--list"]:
        if len(argv) != 2:
            print(__doc__, file=sys.stderr)
            return 2
        with open(argv[1], encoding="utf-8") as f:
            paths = [line.strip() for line in f if line.strip()]
    elif argv and not argv[0].startswith("-"):
        paths = argv
    else:
        print(__doc__, file=sys.stderr)
        return 2

    import mujoco

    # MuJoCo's default warning handler prints to stdout and appends to MUJOCO_LOG.TXT in
    # the working folder: it would corrupt the JSON lines and litter the repository.
    mujoco.set_mju_user_warning(lambda _msg: None)
    for path in paths:
        print(json.dumps(sizes(mujoco, path)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
