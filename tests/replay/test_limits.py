"""replay.limits: the defaults, raising a limit by its environment variable, bad variables."""

from __future__ import annotations

import pytest

from pathlib import Path

from replay.limits import LIMITS, LimitError, check, limit


def test_each_limit_has_a_positive_default_and_an_env_name():
    for name, lim in LIMITS.items():
        assert lim.name == name
        assert lim.default > 0
        assert lim.env == f"REPLAY_LIMIT_{name.upper()}"


def test_over_the_limit_is_one_line_naming_the_limit_and_its_variable(monkeypatch):
    monkeypatch.delenv("REPLAY_LIMIT_CAMERA_PIXELS", raising=False)
    check("camera_pixels", LIMITS["camera_pixels"].default)  # at the limit: fine
    with pytest.raises(LimitError) as err:
        check("camera_pixels", LIMITS["camera_pixels"].default + 1, "sensors.chip: big image")
    text = str(err.value)
    assert "\n" not in text
    assert text.startswith("sensors.chip: big image is 16,777,217 pixels")
    assert "limit of 16,777,216" in text and "REPLAY_LIMIT_CAMERA_PIXELS" in text


@pytest.mark.parametrize("raw", ["10_000_000", " 10000000 "])
def test_the_variable_raises_the_limit(monkeypatch, raw):
    monkeypatch.setenv("REPLAY_LIMIT_CAMERA_PIXELS", raw)
    assert limit("camera_pixels") == 10_000_000
    check("camera_pixels", 9_000_000)


@pytest.mark.parametrize("raw", ["lots", "-5", "0", "1e9"])
def test_a_bad_variable_is_an_error_not_the_default(monkeypatch, raw):
    monkeypatch.setenv("REPLAY_LIMIT_SWEEP_VARIANTS", raw)
    with pytest.raises(LimitError, match="REPLAY_LIMIT_SWEEP_VARIANTS"):
        limit("sweep_variants")


def test_a_huge_integer_is_printed_exactly():
    with pytest.raises(LimitError, match=r"is 1,000,000,000,000,000,000,000,000,000,000 variants"):
        check("sweep_variants", 10**30)


def test_the_security_note_lists_every_limit_with_its_default():
    """docs/security.md's table: one row a limit, its default and variable as in the code."""
    doc = (Path(__file__).resolve().parents[2] / "docs" / "security.md").read_text("utf-8")
    rows = {
        line.split("|")[1].strip(" `"): line
        for line in doc.splitlines()
        if "REPLAY_LIMIT_" in line and line.startswith("| `")
    }
    assert set(rows) == set(LIMITS)
    for name, lim in LIMITS.items():
        assert f"{lim.default:,} {lim.unit}" in rows[name] and lim.env in rows[name], rows[name]
