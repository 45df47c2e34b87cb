"""Tests of optdesign.search: the global search, its starts and its odds."""
