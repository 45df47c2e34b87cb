"""Input checks shared by the models and mechanisms: numeric values only.

Symbolic (CasADi) values pass unchecked: a solver's bounds keep them in range. Errors
name the field (:class:`optdesign.errors.InputError`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError


def _numeric(value: Any) -> np.ndarray | None:
    return None if m.is_symbolic(value) else np.asarray(value, dtype=float)


def require_finite(field: str, value: Any) -> None:
    """Raise InputError naming ``field`` unless the numeric ``value`` is finite."""
    arr = _numeric(value)
    if arr is not None and not np.all(np.isfinite(arr)):
        raise InputError(field, f"must be finite, got {value!r}")


def require_positive(field: str, value: Any) -> None:
    """Raise InputError naming ``field`` unless the numeric ``value`` is finite and > 0."""
    require_finite(field, value)
    arr = _numeric(value)
    if arr is not None and np.any(arr <= 0):
        raise InputError(field, f"must be positive, got {value!r}")


def require_nonnegative(field: str, value: Any) -> None:
    """Raise InputError naming ``field`` unless the numeric ``value`` is finite and >= 0."""
    require_finite(field, value)
    arr = _numeric(value)
    if arr is not None and np.any(arr < 0):
        raise InputError(field, f"must be >= 0, got {value!r}")
