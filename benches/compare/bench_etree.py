"""ElementPath over a robot: mjcf_forge elements against xml.etree on the same tree.

Not a timed test: it prints the time per call of each query, ours and xml.etree's (its C
accelerator over the tree xml.etree reads from our Document.to_xml()), and their ratio;
the goal is within 2x of xml.etree.

Run: python benches/compare/bench_etree.py [model.xml]   (default: robosuite's panda robot)

"cold": the elements found have no Python object yet, so every call makes them (the usual
case of a loop that drops its results); "warm": every element's object is alive (code
keeping handles), so a call finds them.
"""
from __future__ import annotations

import sys
import xml.etree.ElementTree as ET
from pathlib import Path

from mjcf_forge import Document
from timing import per_call  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
PANDA = ROOT / ".cache/corpus/robosuite-1.5.2/robosuite/models/assets/robots/panda/robot.xml"




def main() -> None:
    model = Path(sys.argv[1]) if len(sys.argv) > 1 else PANDA
    doc = Document.load(model)
    ours_root = doc.root
    theirs_root = ET.fromstring(doc.to_xml())
    body = next(b.get("name") for b in theirs_root.iter("body") if b.find("./*[@pos]") is not None and b.get("name"))
    inner = theirs_root.findall(".//body")[-1].get("name")
    queries = [
        ("root", ".//geom"),
        ("root", f".//body[@name='{inner}']"),
        (body, "./*[@pos]"),
        ("root", ".//joint"),
        (body, "geom"),
        ("root", "worldbody"),
        ("root", ".//body/.."),
    ]
    print(f"{model.name}: {len(list(theirs_root.iter()))} elements")
    print(f"{'query':44} {'ours cold':>10} {'ours warm':>10} {'xml.etree':>10} {'cold/ET':>8} {'warm/ET':>8}")
    for context, path in queries:
        if context == "root":
            ours, theirs, label = ours_root, theirs_root, f"root.findall({path!r})"
        else:
            ours = ours_root.find(f".//body[@name='{context}']")
            theirs = theirs_root.find(f".//body[@name='{context}']")
            label = f"<{context}>.findall({path!r})"
        assert [e.items() for e in ours.findall(path)] == [e.items() for e in theirs.findall(path)]
        cold = per_call(lambda: ours.findall(path))
        keep = list(ours_root.iter())  # every element's object alive
        warm = per_call(lambda: ours.findall(path))
        del keep
        et = per_call(lambda: theirs.findall(path))
        print(f"{label:44} {cold * 1e6:9.2f}µ {warm * 1e6:9.2f}µ {et * 1e6:9.2f}µ {cold / et:8.2f} {warm / et:8.2f}")


if __name__ == "__main__":
    main()
