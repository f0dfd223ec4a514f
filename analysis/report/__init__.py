"""The reproduction report (``replay report``): figures, claims and ablations per paper."""

from analysis.report.builder import build_report
from analysis.report.folder import ReportFolderError

__all__ = ["ReportFolderError", "build_report"]
