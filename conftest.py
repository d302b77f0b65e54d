"""pytest's configuration for the whole suite: tests/ and the doctests of projeq/ (pyproject.toml)."""

import gc


def pytest_runtest_setup(item):
    """Collect garbage before each doctest. sympy's lambdify puts its generated source in
    linecache and deletes the entry when the function is garbage-collected; doctest starts every
    example's run with linecache.checkcache(), which in Python 3.11 iterates a snapshot of the
    cache's keys and raises KeyError when a collection inside that loop deletes one of them (seen
    in CI: KeyError '<lambdifygenerated-1642>' in projeq/scenes/parameters.py's doctest). After a
    collection here, no lambdified function is left to die inside the loop."""
    if type(item).__name__ == "DoctestItem":
        gc.collect()
