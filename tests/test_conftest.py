"""tests/conftest.py's own data."""

from conftest import LONGEST_FIRST, ROOT


def test_the_longest_files_listed_exist():
    missing = [p for p in LONGEST_FIRST if not (ROOT / p).is_file()]
    assert not missing, f"LONGEST_FIRST names files that are gone: {missing}"
    assert len(set(LONGEST_FIRST)) == len(LONGEST_FIRST)
