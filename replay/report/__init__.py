"""The reproduction report (``replay report``): figures, claims and ablations per paper."""

from replay.report.builder import build_report

__all__ = ["build_report"]
