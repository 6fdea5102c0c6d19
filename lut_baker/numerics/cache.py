"""A least-recently-used cache for values whose inputs ``functools.lru_cache`` cannot take.

``functools.lru_cache`` memoises a function of hashable arguments; :class:`LRUCache` is for the
other cases: the key is built from arrays or records by the caller, or only some results may
be kept.  Plain Python (it runs inside Blender).  Safe to share between threads (the add-on
bakes and fits on a worker thread): every read and write holds a lock; a value is computed
outside it, so two threads asking for the same missing key may both compute it (the last
stored wins; both are the same value).

Types
-----
- :class:`LRUCache` -- at most ``size`` values by hashable key, the least recently used
  dropped first.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import Any, TypeVar

__all__ = ["LRUCache"]

_T = TypeVar("_T")


class LRUCache:
    """At most ``size`` values (None: no limit) by hashable key; reading or storing a key makes
    it the most recently used, and storing beyond ``size`` drops the least recently used."""

    def __init__(self, size: int | None) -> None:
        if size is not None and size < 1:
            raise ValueError(f"size must be >= 1 or None, got {size!r}")
        self.size = size
        self._values: OrderedDict[Hashable, Any] = OrderedDict()
        self._lock = threading.RLock()

    def __len__(self) -> int:
        with self._lock:
            return len(self._values)

    def __contains__(self, key: object) -> bool:
        with self._lock:
            return key in self._values

    def get(self, key: Hashable, default: Any = None) -> Any:
        """The value stored under ``key`` (now the most recently used), else ``default``."""
        with self._lock:
            if key not in self._values:
                return default
            self._values.move_to_end(key)
            return self._values[key]

    def put(self, key: Hashable, value: Any) -> None:
        """Store ``value`` under ``key``, dropping the least recently used beyond ``size``."""
        with self._lock:
            self._values[key] = value
            self._values.move_to_end(key)
            while self.size is not None and len(self._values) > self.size:
                self._values.popitem(last=False)

    def get_or_compute(self, key: Hashable, compute: Callable[[], _T]) -> _T:
        """The value under ``key``; if there is none, ``compute()`` (outside the lock)
        stored under it first."""
        missing = object()
        value = self.get(key, missing)
        if value is not missing:
            return value
        value = compute()
        self.put(key, value)
        return value

    def clear(self) -> None:
        """Forget every value."""
        with self._lock:
            self._values.clear()
