"""mjcf_forge: MuJoCo MJCF models loaded exactly as MuJoCo reads them, in Rust.

- :class:`Document`: a model with its includes expanded, default classes inlined and
  asset paths absolute (a URDF robot read as MuJoCo's importer reads it, or with
  :meth:`Document.from_urdf`'s options: visuals, static links, ``package://`` folders,
  actuators); prefix, merge, validate, write; its :class:`Element` s behave as
  ``xml.etree.ElementTree`` elements (ElementPath, live ``attrib``, ``append``, ...), and
  :mod:`mjcf_forge.etree` mirrors ``xml.etree.ElementTree``'s functions over them.
- :class:`Model`: one instance of a model with its own name prefix and robosuite's
  vocabulary (``bodies``, ``joints``, ``contact_geoms``, ``bottom_offset``, ...).
- :class:`Scene`: a randomized scene description; ``scene.variant(i)`` is variant ``i``
  (the same bytes for the same seed and index, whatever the thread count), and
  ``scene.variants(indices, threads=...)`` generates many on Rust threads.
- :class:`ModelCache`: compiled models of a scene's variants at patch cost: one compile
  per structure (``variant.structure_key``), then ``variant.patch`` written into it.
- :class:`DocumentCache`: the same for any document or MJCF text: its structure
  (``doc.structure_key``) and patch (``doc.patch``) found by reading it.
- :class:`LoadCache`: loaded files served again, copied, while unchanged.
- :class:`MjcfError`: the package's exception (a ``ValueError``), with ``.errors``;
  :class:`MjcfFileNotFoundError` is both an :class:`MjcfError` and a
  ``FileNotFoundError``, for a file that does not exist. Arguments of the wrong type
  raise ``TypeError``, a variant index out of range ``IndexError``.
- :mod:`mjcf_forge.base`: robosuite's ``MujocoXML``, ``MujocoModel`` and
  ``MujocoXMLModel`` (``robosuite.models.base``) over documents, for code written for
  robosuite (its ``XMLError`` is an :class:`MjcfError`); ``mjcf_forge.robosuite.use()``,
  called before robosuite is imported, makes robosuite's own classes build on them.
"""

from ._mjcf_forge import (
    Attrib,
    Document,
    Element,
    LoadCache,
    MergeReport,
    MjcfError,
    Model,
    Scene,
    Superset,
    Variant,
    VariantIterator,
    __version__,
)
from ._errors import MjcfFileNotFoundError
from ._cache import ModelCache
from ._doc_cache import DocumentCache
from . import etree
from . import base

__all__ = [
    "Attrib",
    "Document",
    "DocumentCache",
    "Element",
    "LoadCache",
    "MergeReport",
    "MjcfError",
    "MjcfFileNotFoundError",
    "Model",
    "ModelCache",
    "Scene",
    "Superset",
    "Variant",
    "VariantIterator",
    "__version__",
]
