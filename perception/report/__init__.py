"""Recognition reports: per clip (JSON, CSV, figures) and per batch (tables, statistics, HTML)."""

from perception.report.batch import BatchReport, write_batch_report
from perception.report.clip import ClipSummary, clip_outputs, write_clip_report
from perception.report.conditions import PROFILE_POINTS, condition_profiles, condition_statistics
from perception.report.figures import condition_figure, confidence_figure, paths_figure

__all__ = [
    "BatchReport",
    "ClipSummary",
    "PROFILE_POINTS",
    "clip_outputs",
    "condition_figure",
    "condition_profiles",
    "condition_statistics",
    "confidence_figure",
    "paths_figure",
    "write_batch_report",
    "write_clip_report",
]
