"""Writing files whole: what the package writes (models, contact sheets) appears complete
or not at all."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Union


def write_atomic(path: Union[str, os.PathLike], data: bytes) -> None:
    """Writes ``data`` to ``path`` through a temporary file in the same folder and a
    rename: a reader never sees a partial file, and a failure leaves the old one.

    Example::

        write_atomic("out/model.xml", text.encode())
    """
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=".mjcf-forge-", suffix=Path(path).suffix)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
