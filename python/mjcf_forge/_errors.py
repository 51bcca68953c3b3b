"""The package's exceptions made on the Python side.

- :class:`MjcfFileNotFoundError`: two standard exceptions at once; the compiled module
  raises it (``errors.rs``) where every problem of a refusal is a file that does not
  exist.
- :class:`XMLError` (:mod:`mjcf_forge.base`'s, robosuite's ``XMLError``) and
  :func:`xml_error`, which makes one that is robosuite's too once robosuite is imported.
- :func:`error`: a plain :class:`MjcfError` with its ``errors`` line.
"""

from __future__ import annotations

import sys
from typing import Any, Optional

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


def error(message: str) -> MjcfError:
    """An :class:`MjcfError` told by ``message`` (its one ``errors`` line)."""
    err = MjcfError(message)
    err.errors = [message]
    return err


class XMLError(MjcfError):
    """A model or merge that :mod:`mjcf_forge.base` refuses (robosuite's ``XMLError``).

    An :class:`~mjcf_forge.MjcfError`, hence a ``ValueError``; ``errors`` holds the
    message's lines. Raised errors are also instances of robosuite's
    ``robosuite.utils.errors.XMLError`` whenever that module is imported: the class raised
    is then a subclass of both (made once, also named ``XMLError``), so ``except
    XMLError`` works with either import.
    """

    __module__ = "mjcf_forge.base"


# One class per robosuite XMLError met: subclass of ours and of it.
_FLAVOURS: dict = {}


def _robosuite_xml_error() -> Optional[type]:
    """robosuite's XMLError if robosuite is imported and ours is not already one."""
    module = sys.modules.get("robosuite.utils.errors")
    theirs = getattr(module, "XMLError", None)
    if (
        isinstance(theirs, type)
        and issubclass(theirs, BaseException)
        and not issubclass(XMLError, theirs)
    ):
        return theirs
    return None


def xml_error(message: str, errors: Optional[list] = None) -> XMLError:
    """An :class:`XMLError` carrying ``message`` (and ``errors``, default: its lines),
    also robosuite's ``XMLError`` when robosuite is imported.

    >>> xml_error("two lines\\nof trouble").errors
    ['two lines', 'of trouble']
    """
    cls: type = XMLError
    theirs = _robosuite_xml_error()
    if theirs is not None:
        cls = _FLAVOURS.get(theirs)
        if cls is None:
            cls = type(
                "XMLError",
                (XMLError, theirs),
                {"__module__": XMLError.__module__, "__doc__": XMLError.__doc__},
            )
            _FLAVOURS[theirs] = cls
    err = cls(message)
    err.errors = list(errors) if errors else str(message).splitlines() or [str(message)]
    return err


def reraised(err: MjcfError) -> XMLError:
    """``err`` as an :class:`XMLError`, its message and lines kept."""
    return xml_error(str(err), getattr(err, "errors", None))
