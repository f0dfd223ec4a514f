"""Foxglove's and Rerun's view of a run: the well-known topics a log holds beside its JSON
contract topics (docs/foxglove.md): ``topics`` writes them, ``run`` feeds them from the runner,
``schemas`` encodes and decodes them, ``png`` encodes the camera images."""
