"""Foxglove's and Rerun's view of a run: the well-known topics a log holds beside its JSON
contract topics (docs/foxglove.md): ``topics`` writes them, ``run`` feeds them from the runner,
``schemas`` names their schemas and decodes them, ``image`` makes the camera images'
messages."""
