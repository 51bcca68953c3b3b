"""The exception that is two standard ones at once: :class:`MjcfFileNotFoundError`.

The compiled module raises it (``errors.rs``) where every problem of a refusal is a file
that does not exist. And ``_error``: an :class:`MjcfError` made on the Python side.
"""

from __future__ import annotations

from typing import Any

from ._mjcf_forge import MjcfError


class MjcfFileNotFoundError(MjcfError, FileNotFoundError):
    """A file that does not exist: an :class:`MjcfError` (the same message, one
    ``file:line:col: message`` line per problem, and the same ``errors``) and a
    ``FileNotFoundError`` (``errno`` is ``errno.ENOENT``, ``filename`` the first missing
    path), so that ``except FileNotFoundError``, ``except OSError``, ``except MjcfError``
    and ``except ValueError`` all catch it.

    Raised when every problem of a refusal is a missing file: a model or scene file, an
    included file, a model that a scene names.
    """

    __module__ = "mjcf_forge"

    # OSError's would print "[Errno 2] ..." instead of our lines.
    __str__ = BaseException.__str__

    def __reduce__(self) -> Any:
        # OSError's rebuilds from (errno, strerror, filename), which would change the
        # message: the message, then the attributes.
        state = dict(self.__dict__, errno=self.errno, filename=self.filename)
        return (type(self), self.args[:1], state)


def _error(message: str) -> MjcfError:
    err = MjcfError(message)
    err.errors = [message]
    return err
