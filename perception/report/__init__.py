"""Recognition reports: per clip (JSON, CSV, figures) and per batch (tables, statistics, HTML).

The names below load their module on first use (PEP 562): ``recognize``
writes a clip's report without importing the batch report's pandas and
statistics, which cost half a second a process.
"""

import importlib

_HOMES = {
    "batch": ("BatchReport", "write_batch_report"),
    "chart": ("Band", "Chart", "ErrorBars", "Legend", "Line", "Panel", "render_png",
              "to_matplotlib"),
    "clip": ("ClipSummary", "clip_figures", "clip_outputs", "write_clip_report"),
    "conditions": ("PROFILE_POINTS", "aperture_profiles", "condition_profiles",
                   "condition_statistics", "reference_model"),
    "figures": ("aperture_chart", "aperture_figure", "condition_chart", "condition_figure",
                "confidence_all_chart", "confidence_all_figure", "confidence_chart",
                "confidence_figure", "confidence_single_chart", "confidence_single_figure",
                "paths_chart", "paths_figure"),
}
_MODULE_OF = {name: module for module, names in _HOMES.items() for name in names}

__all__ = sorted(_MODULE_OF)


def __getattr__(name: str):
    if name not in _MODULE_OF:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{_MODULE_OF[name]}"), name)
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
