"""numpy arrays of the extension's ``(dtype, buffer, shape)`` triples (no copy, writable)."""

from __future__ import annotations

from typing import Any, Dict, Tuple

import numpy as np


def array(packed: Tuple[str, bytearray, list]) -> np.ndarray:
    dtype, buffer, shape = packed
    return np.frombuffer(buffer, dtype=np.dtype(dtype)).reshape(shape)


def arrays(packed: Dict[str, Any]) -> Dict[str, Any]:
    """A dict whose packed values (and those of nested dicts) are made numpy arrays."""
    out: Dict[str, Any] = {}
    for key, value in packed.items():
        if isinstance(value, dict):
            out[key] = arrays(value)
        elif isinstance(value, tuple) and len(value) == 3 and isinstance(value[1], bytearray):
            out[key] = array(value)
        else:
            out[key] = value
    return out
