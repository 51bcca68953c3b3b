"""What differs between the versions of the user's ``mujoco`` the caches run on (3.3 to
4.0), in one place: the rest of the package asks here instead of testing for fields.

- the joint-space inertia: ``mj_makeM`` where MuJoCo has it, else ``mj_crb`` (3.3),
  which fills ``qM`` the same way;
- its diagonal: the last entry of each row of ``data.M`` (sparse rows: ``M_rowadr``,
  ``M_rownnz``, from 3.9 or so), else ``data.qM`` at ``dof_Madr`` (3.3: the same numbers);
- fields some versions do not have (``dof_length``, ``body_simple``, ``M_rownnz``):
  :func:`field` gives ``None`` for them;
- which of a model's arrays are bulk data (:func:`restored_arrays`: the rest), the
  number fields of its structs (:func:`struct_fields`) and the parts of ``mjVisual``.
"""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

from ._mjcf_forge import BULK_PREFIXES, BULK_SIZES


def make_inertia(mujoco: Any, model: Any, data: Any) -> None:
    """Fills ``data``'s joint-space inertia (``qM``, and ``M`` where MuJoCo has it) from
    its kinematics."""
    (getattr(mujoco, "mj_makeM", None) or mujoco.mj_crb)(model, data)


def inertia_diagonal(model: Any, data: Any) -> tuple[np.ndarray, np.ndarray]:
    """The array that holds ``data``'s joint-space inertia and the indices of its
    diagonal in it (one per degree of freedom), live: read after :func:`make_inertia`."""
    if hasattr(data, "M"):
        return data.M, model.M_rowadr + model.M_rownnz - 1
    return data.qM, model.dof_Madr.copy()


def field(obj: Any, name: str) -> Any:
    """``obj.name`` (a model's or data's field), or ``None`` where this MuJoCo has none."""
    return getattr(obj, name, None)


# The sizes that count rows of mesh, texture, height field, skin and bounding-volume data
# (BULK_SIZES), and the same arrays by name for a mujoco without introspection
# (BULK_PREFIXES): the split tier's tables (mjcf_forge::split, through the extension). No
# patch writes them and they are most of a model's bytes (70 MB of lift5's 70.5), so they
# are not restored before a patch (see DocumentCache).
_BULK_SIZES = frozenset(BULK_SIZES)
# The parts of mjVisual, each a struct of numbers.
VISUAL = ("global_", "quality", "headlight", "map", "scale", "rgba")


def restored_arrays(mujoco: Any, model: Any) -> list[str]:
    """The arrays of ``model`` but the bulk data (mesh, texture, height-field, skin and
    bounding-volume data): what a patch may write and ``mj_copyBack`` reads, but height
    fields' data."""
    try:
        from mujoco.introspect import structs

        fields = structs.STRUCTS["mjModel"].fields
        names = [
            f.name
            for f in fields
            if getattr(f, "array_extent", None) and str(f.array_extent[0]) not in _BULK_SIZES
        ]
    except (ImportError, KeyError, AttributeError):
        names = [n for n in dir(model) if not n.startswith(("_",) + BULK_PREFIXES)]
    return [n for n in names if isinstance(getattr(model, n, None), np.ndarray)]


def snapshot_fields(mujoco: Any, model: Any) -> list[tuple[tuple[str, ...], str]]:
    """What ``DocumentCache`` writes back into a model before each patch, as
    ``(path, name)`` pairs (``model.<path...>.<name>``): every array but the bulk data
    (:func:`restored_arrays`), and the numbers of ``model.opt`` and ``model.vis``.

    >>> import mujoco
    >>> model = mujoco.MjModel.from_xml_string("<mujoco/>")
    >>> fields = snapshot_fields(mujoco, model)
    >>> ((), "body_mass") in fields, (("opt",), "timestep") in fields
    (True, True)
    """
    fields: list[tuple[tuple[str, ...], str]] = [((), n) for n in restored_arrays(mujoco, model)]
    for path in [("opt",)] + [("vis", v) for v in VISUAL]:
        obj = model
        for part in path:
            obj = getattr(obj, part, None)
        if obj is not None:
            fields.extend((path, n) for n in struct_fields(obj))
    return fields


# C sizes of the scalar types mjModel's fields are declared with (mujoco.introspect).
_C_SIZES = {"int": 4, "unsigned int": 4, "float": 4, "mjtNum": 8, "double": 8, "mjtSize": 8,
            "uint64_t": 8, "int64_t": 8, "size_t": 8, "mjtBool": 1, "mjtByte": 1, "char": 1,
            "unsigned char": 1}
_SIGNATURE_AT: dict = {}


def _c_layout(fields: Any, structs: Any) -> tuple[int, int, dict]:
    """A C struct's size, alignment and field offsets from its introspected fields."""
    offset, align, offsets = 0, 1, {}
    for f in fields:
        size, a = _c_type(f.type, structs)
        offset = (offset + a - 1) // a * a
        offsets[f.name] = offset
        offset += size
        align = max(align, a)
    return (offset + align - 1) // align * align, align, offsets


def _c_type(t: Any, structs: Any) -> tuple[int, int]:
    kind = type(t).__name__
    if kind == "PointerType":
        return 8, 8
    if kind == "ArrayType":
        size, a = _c_type(t.inner_type, structs)
        for e in t.extents:
            size *= int(e)
        return size, a
    if kind == "AnonymousStructDecl":
        return _c_layout(t.fields, structs)[:2]
    if t.name in _C_SIZES:
        return _C_SIZES[t.name], _C_SIZES[t.name]
    return _c_layout(structs[t.name].fields, structs)[:2]


def signature_offset(mujoco: Any) -> Optional[int]:
    """Where ``mjModel.signature`` sits in the struct (which MuJoCo's binary format does
    not keep, and the bindings do not let set): from the headers' layout as
    ``mujoco.introspect`` declares it, checked on two models; ``None`` when it cannot be."""
    version = str(getattr(mujoco, "__version__", ""))
    if version not in _SIGNATURE_AT:
        found = None
        try:
            import ctypes

            from mujoco.introspect import structs

            offset = _c_layout(structs.STRUCTS["mjModel"].fields, structs.STRUCTS)[2]["signature"]
            probes = [mujoco.MjModel.from_xml_string(x) for x in (
                "<mujoco><worldbody><geom size='1'/></worldbody></mujoco>",
                "<mujoco><worldbody><body><joint/><geom size='1'/></body></worldbody></mujoco>")]
            sigs = [ctypes.c_uint64.from_address(p._address + offset).value for p in probes]
            if sigs == [p.signature for p in probes] and sigs[0] != sigs[1] and 0 not in sigs:
                found = offset
        except Exception:  # an introspection this code does not know: no store
            found = None
        _SIGNATURE_AT[version] = found
    return _SIGNATURE_AT[version]


def model_bytes(mujoco: Any, model: Any) -> bytearray:
    """``model`` as the model store keeps it: its signature (8 bytes, little-endian), then
    MuJoCo's binary format (``mj_saveModel``), which does not hold the signature."""
    out = bytearray(8 + mujoco.mj_sizeModel(model))
    out[:8] = int(model.signature).to_bytes(8, "little")
    # Written in place after the signature: the model's bytes made once (a store entry of
    # LIBERO's is 270 MB).
    mujoco.mj_saveModel(model, None, np.frombuffer(out, dtype=np.uint8, offset=8))
    return out


def model_from_bytes(mujoco: Any, data: bytes, signature: Optional[int] = None) -> Any:
    """The model :func:`model_bytes` wrote, read back by ``mujoco`` (through its VFS) with
    its signature, or ``None``. With ``signature`` given, ``data`` is MuJoCo's binary
    model alone (the store's reader splits them: no copy of the model's bytes here).

    >>> import mujoco
    >>> m = mujoco.MjModel.from_xml_string("<mujoco><worldbody><geom size='1'/></worldbody></mujoco>")
    >>> back = model_from_bytes(mujoco, model_bytes(mujoco, m))
    >>> back.signature == m.signature, back.geom_size.tolist() == m.geom_size.tolist()
    (True, True)
    """
    import ctypes

    offset = signature_offset(mujoco)
    if signature is None:
        if offset is None or len(data) < 8:
            return None
        signature, data = int.from_bytes(data[:8], "little"), bytes(data[8:])
    if offset is None:
        return None
    model = mujoco.MjModel.from_binary_path("model.mjb", {"model.mjb": data})
    ctypes.c_uint64.from_address(model._address + offset).value = signature
    return model if model.signature == signature else None


def struct_fields(obj: Any) -> list[str]:
    """The number fields of a struct of the bindings (``model.opt``, ``model.vis.map``)."""
    return [
        n
        for n in dir(obj)
        if not n.startswith("_")
        and isinstance(getattr(obj, n, None), (int, float, np.ndarray))
        and not callable(getattr(obj, n))
    ]


def version_tuple(version: Any) -> Optional[tuple]:
    """A MuJoCo version's (major, minor), or ``None`` where it is not one
    (``"3.16.0"`` -> ``(3, 16)``)."""
    try:
        parts = tuple(int(p) for p in str(version or "").split(".")[:2])
    except ValueError:
        return None
    return parts if len(parts) == 2 else None
