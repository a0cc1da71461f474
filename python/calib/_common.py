"""What the wrappers share: the warning class and path handling."""

from __future__ import annotations

import os
import warnings
from typing import Iterable, Union

PathLike = Union[str, "os.PathLike[str]"]


class CalibWarning(UserWarning):
    """What the CLI prints as ``warning: …``: the result stands, but deserves caution."""


def warn_all(messages: Iterable[str], stacklevel: int = 3) -> None:
    """Issues each message as a :class:`CalibWarning`."""
    for message in messages:
        warnings.warn(message, CalibWarning, stacklevel=stacklevel)


def is_path(value: object) -> bool:
    """Whether ``value`` names a file."""
    return isinstance(value, (str, os.PathLike))
