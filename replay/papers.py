"""The papers this platform reproduces, by the key a scenario's ``paper:`` field uses."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Paper:
    key: str
    title: str
    authors: str
    text: str  # file under shared/papers/


PAPERS = {
    "higashimori2007": Paper(
        "higashimori2007",
        "Friction Independent Dynamic Capturing Strategy for a 2D Stick-shaped Object",
        "Higashimori, Kimura, Ishii & Kaneko",
        "002_9fb29b566fa62b9e.txt",
    ),
    "namiki2003": Paper(
        "namiki2003",
        "Robotic Catching Using a Direct Mapping from Visual Information to Motor Command",
        "Namiki & Ishikawa",
        "000_e268676ea4c8a813.txt",
    ),
    "namiki1999": Paper(
        "namiki1999",
        "High Speed Grasping Using Visual and Force Feedback",
        "Namiki, Nakabo, Ishii & Ishikawa",
        "004_9b0d52b607ebcc1f.txt",
    ),
}
