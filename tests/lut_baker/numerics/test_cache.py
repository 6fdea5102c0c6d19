"""lut_baker.numerics.cache: the LRU cache."""

import pytest

from lut_baker.numerics.cache import LRUCache


def test_lru_cache_drops_the_least_recently_used():
    cache = LRUCache(2)
    cache.put("a", 1)
    cache.put("b", 2)
    assert cache.get("a") == 1  # "b" is now the least recently used
    cache.put("c", 3)
    assert "b" not in cache and len(cache) == 2
    calls = []
    assert cache.get_or_compute("d", lambda: calls.append(1) or 4) == 4
    assert cache.get_or_compute("d", lambda: calls.append(1) or 5) == 4 and calls == [1]
    assert cache.get("zzz", "none") == "none"
    cache.clear()
    assert len(cache) == 0
    unbounded = LRUCache(None)
    for i in range(100):
        unbounded.put(i, i)
    assert len(unbounded) == 100
    with pytest.raises(ValueError):
        LRUCache(0)
