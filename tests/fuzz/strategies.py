"""Strategies for bad (and good) input: JSON-like junk and values at the edges of their types."""

from __future__ import annotations

from hypothesis import strategies as st

#: Numbers at every edge: NaN, ±inf, huge and tiny, negative, zero, big integers.
numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.sampled_from([0, 1, -1, 0.5, 1e-300, 1e300, 2**31, -(2**31) - 1, 2**63]),
)
scalars = st.none() | st.booleans() | numbers | st.text(max_size=8)
#: Any JSON-like value, nested a little.
junk = st.recursive(
    scalars,
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner, max_size=3)
    ),
    max_leaves=10,
)


def near(value: float) -> st.SearchStrategy:
    """Values around a sensible ``value`` (and junk): most cases should be valid."""
    return st.one_of(
        st.floats(min_value=min(0.5 * value, 2 * value), max_value=max(0.5 * value, 2 * value)),
        st.just(value),
        numbers,
        junk,
    )
