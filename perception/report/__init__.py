"""Recognition reports: per clip (JSON, CSV, figures) and per batch (tables, statistics, HTML)."""

from perception.report.batch import BatchReport, write_batch_report
from perception.report.clip import ClipSummary, clip_figures, clip_outputs, write_clip_report
from perception.report.conditions import (
    PROFILE_POINTS,
    aperture_profiles,
    condition_profiles,
    condition_statistics,
    reference_model,
)
from perception.report.figures import (
    aperture_figure,
    condition_figure,
    confidence_all_figure,
    confidence_figure,
    confidence_single_figure,
    paths_figure,
)

__all__ = [
    "BatchReport",
    "ClipSummary",
    "PROFILE_POINTS",
    "aperture_figure",
    "aperture_profiles",
    "clip_figures",
    "clip_outputs",
    "condition_figure",
    "condition_profiles",
    "condition_statistics",
    "confidence_all_figure",
    "confidence_figure",
    "confidence_single_figure",
    "paths_figure",
    "reference_model",
    "write_batch_report",
    "write_clip_report",
]
