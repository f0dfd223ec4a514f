"""The reproduction report (``replay report``): figures, claims and ablations per paper."""

from replay.report.builder import build_report
from replay.report.folder import ReportFolderError

__all__ = ["ReportFolderError", "build_report"]
