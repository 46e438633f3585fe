"""The examples in the docstrings run and print what they say."""

from __future__ import annotations

import doctest

import spectral_skin as ss


def test_docstring_examples():
    result = doctest.testmod(ss, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted >= 20
    assert result.failed == 0
