"""Package data of an installed wheel: data/ and scenarios/ (see replay.resources)."""
