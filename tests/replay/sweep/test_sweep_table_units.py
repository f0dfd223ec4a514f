"""table.csv says each known column's unit in its header; tables with or without units load alike."""

import csv

from replay.resources import data_path
from replay.sweep.table import read_table, write_table


ROW = {
    "index": 0,
    "key": "abc",
    "mass": 1.5,
    "seed": 3,
    "success": True,
    "reason": "caught",
    "m.contact_speed": 2.25,
    "m.mapping": "optimised",
    "e.catch": 1,
    "stopped_by": "catch",
    "t_end": 0.47,
    "wall_time": 0.5,
    "cpu_time": 0.4,
    "log": "",
    "version": "v",
}


def test_the_header_has_units_and_the_rows_read_back_by_name(tmp_path):
    path = tmp_path / "table.csv"
    write_table(path, [ROW], ["mass"])
    with path.open(newline="") as f:
        head = next(csv.reader(f))
    assert head[:3] == ["index", "key", "mass"]  # (no unit known: the name alone)
    assert {"t_end [s]", "cpu_time [s]", "e.catch [1]", "m.contact_speed [m/s]"} <= set(head)
    assert "m.mapping" in head and "seed" in head
    (row,) = read_table(path)
    assert row["t_end"] == "0.47" and row["m.contact_speed"] == "2.25" and row["e.catch"] == "1"
    assert set(row) == set(ROW)


def test_measured_numbers_have_six_significant_digits_and_parameters_stay(tmp_path):
    path = tmp_path / "table.csv"
    row = {**ROW, "mass": 1.23456789012, "m.contact_speed": 2.735147272497597, "t_end": 0.1 + 0.2}
    write_table(path, [row], ["mass"])
    (back,) = read_table(path)
    assert back["m.contact_speed"] == "2.73515" and back["t_end"] == "0.3"
    assert float(back["mass"]) == row["mass"]  # (a cell's key: never rounded)


def test_a_header_without_units_reads_the_same(tmp_path):
    path = tmp_path / "table.csv"
    write_table(path, [ROW], ["mass"])
    with path.open(newline="") as f:
        lines = list(csv.reader(f))
    plain = tmp_path / "plain.csv"
    with plain.open("w", newline="") as f:
        csv.writer(f).writerows([[h.split(" [")[0] for h in lines[0]], *lines[1:]])
    assert read_table(plain) == read_table(path)


def test_the_stored_ablation_tables_still_load():
    tables = [
        p
        for p in sorted(data_path("ablations").glob("*.csv"))
        if p.read_text(encoding="utf-8").startswith("index,key,")  # (a sweep's, not a claim's)
    ]
    assert len(tables) >= 10
    for stored in tables:
        rows = read_table(stored)
        assert rows and all("t_end" in r and "success" in r for r in rows), stored.name
