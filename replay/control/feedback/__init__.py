"""Simple visual feedback for the catching arm (Namiki & Ishikawa 2003, Sec. IV-B: "it is
difficult to catch it only using simple feedback control"): the comparison their claim implies.
"""

from replay.control.feedback.controller import FeedbackController, FeedbackParams

__all__ = ["FeedbackController", "FeedbackParams"]
