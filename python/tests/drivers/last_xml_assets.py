"""Writes ``env.sim.model.get_xml()``'s source, ``mujoco.mj_saveLastXML``, after a sequence
of robosuite ``MujocoXML.get_model()`` calls, stock or on the switch
(``mjcf_forge.robosuite.use()``): run by test_last_xml_assets.py in the robosuite venvs,
whose MuJoCo (3.3.1, 3.9.0) writes which meshes a load read from disk rather than from
MuJoCo's asset cache. One sequence per process: the asset cache is the process's.

    python last_xml_assets.py {stock|switch} SEQUENCE FOLDER OUT

``FOLDER`` holds ``part.xml`` and ``scene.xml`` (the part's mesh and one of its own). The
sequences: ``once`` (the scene's model once), ``twice`` (twice, the second with another
colour), ``part-then-scene`` (the part's model, then the scene's once). ``OUT`` gets the
text written, or ``error: <message>`` where the switch refuses to write.
"""
from __future__ import annotations

import os
import sys

mode, sequence, folder, out = sys.argv[1:5]
if mode == "switch":
    import mjcf_forge.robosuite

    mjcf_forge.robosuite.use()

import mujoco  # noqa: E402
from robosuite.models.base import MujocoXML  # noqa: E402


def model(name: str, rgba: str = "") -> object:
    xml = MujocoXML(os.path.join(folder, name))
    if rgba:
        xml.worldbody.find(".//geom").set("rgba", rgba)
    return xml.get_model(mode="mujoco")


steps = {
    "once": [("scene.xml", "")],
    "twice": [("scene.xml", ""), ("scene.xml", "0 1 0 1")],
    "part-then-scene": [("part.xml", ""), ("scene.xml", "")],
}[sequence]
for name, rgba in steps:
    m = model(name, rgba)
try:
    mujoco.mj_saveLastXML(out + ".xml", m)
    text = open(out + ".xml").read()
except Exception as e:  # noqa: BLE001 - the test reads what was refused
    text = f"error: {type(e).__name__}: {e}"
with open(out, "w") as f:
    f.write(text)
print("ok")
