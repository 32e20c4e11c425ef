"""core.memo: the per-process caches of the numbering's grids and of the warm starts' roots."""

from stcs_ident.core.memo import BoundedCache, model_key


def test_the_oldest_key_is_dropped_and_a_key_put_again_is_the_newest():
    cache = BoundedCache(2)
    cache.put("a", 1)
    cache.put("b", 2)
    cache.put("a", 3)  # "a" is now the newest: "b" goes first
    cache.put("c", 4)
    assert (cache.get("a"), cache.get("b"), cache.get("c"), len(cache)) == (3, None, 4, 2)
    cache.clear()
    assert len(cache) == 0 and cache.get("a", "none") == "none"


def test_an_unhashable_model_has_no_key_and_is_never_kept():
    assert model_key("cable", (1.0, 2.0), "in") == ("cable", (1.0, 2.0), "in")
    key = model_key("cable", {"plane": "in"})  # a dict cannot be hashed
    assert key is None
    cache = BoundedCache(4)
    cache.put(key, 1)
    assert len(cache) == 0 and cache.get(key) is None
