"""Static view of :mod:`perception.report`'s lazily loaded names (lazy_loader reads it)."""

from .batch import BatchReport as BatchReport
from .batch import write_batch_report as write_batch_report
from .clip import ClipSummary as ClipSummary
from .clip import clip_figures as clip_figures
from .clip import clip_outputs as clip_outputs
from .clip import write_clip_report as write_clip_report
from .conditions import PROFILE_POINTS as PROFILE_POINTS
from .conditions import aperture_profiles as aperture_profiles
from .conditions import condition_profiles as condition_profiles
from .conditions import condition_statistics as condition_statistics
from .conditions import reference_model as reference_model
from .figures import aperture_figure as aperture_figure
from .figures import condition_figure as condition_figure
from .figures import confidence_all_figure as confidence_all_figure
from .figures import confidence_figure as confidence_figure
from .figures import confidence_single_figure as confidence_single_figure
from .figures import paths_figure as paths_figure
from .kinematics import kinematics_figure as kinematics_figure
