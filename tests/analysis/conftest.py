"""The feedback baseline's controller (replay/control/feedback) is an entry point in
pyproject.toml; an editable install made before it existed does not list it, so register it
for this process (harmless once installed: the same class)."""

from replay import registry
from replay.control.feedback import FeedbackController

registry.register("controller", "feedback", FeedbackController)
