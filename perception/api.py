"""The public face of :mod:`perception`: what a user calls, in one flat namespace.

::

    import perception as pc

    tracks_file = pc.track_video("clip.mp4")              # video -> <clip>.tracks.h5
    tracks = pc.Tracks.load(tracks_file)                    # positions, likelihood, status
    obs = pc.observe(tracks)                                # model frame, movement span
    rep = pc.Repertoire.build()                             # or pc.Repertoire.load("rep.h5")
    rec = pc.recognize_clip("clip.mp4", rep)                # the whole chain in one call
    moves = pc.load_movements("trials.tsv").records       # any input, in metres
    rec.winner, rec.to_pandas()
    pc.run_batch(pc.discover("clips/"), "report/", rep)    # many clips -> report.html

Everything here is importable from ``perception`` directly; the topic
modules hold the rest.
"""

from perception.batch import BatchItem, discover, run_batch
from perception.errors import HammerMVError, InputError, PlanningError, TrackingError
from perception.geometry import DEFAULT_OBJECT_DIAMETER, SimilarityTransform
from perception.io.tracks import Status, Tracks, TracksWriter
from perception.io.video import FrameSource, open_source, open_video, write_video
from perception.landmarks import LandmarkParams, Landmarks
from perception.loading import load_movements
from perception.measure import landmarks
from perception.observation import (
    MovementSpan,
    Observation,
    ObserveParams,
    movement_record,
    movement_span,
    observe,
)
from perception.online import OnlineRecognizer, SettleRule
from perception.pipeline import RecognitionSettings, load_clip, recognize_clip
from perception.reaches import MarkerMap
from perception.recognition import (
    HammerParams,
    ModelSpec,
    MotorModel,
    Recognition,
    Repertoire,
    SceneSpec,
    recognize,
)
from perception.recognition.engine import StepScorer
from perception.recognition.rules import VerdictRules, judge
from perception.recordings import MocapImport, read_reaches, recognize_reach
from perception.records import MovementRecord
from perception.report import write_batch_report, write_clip_report
from perception.synthetic.demos import demo_tracks
from perception.synthetic.recipes import load_recipe, synthesize
from perception.synthetic.render import render_clip
from perception.synthetic.scene import Camera, RenderStyle, Scene
from perception.tracking.markers import MarkerSet, default_markers
from perception.tracking.tracker import Tracker, TrackerParams
from perception.tracking.video_tracks import track_video

__all__ = [
    "MocapImport",
    "MarkerMap",
    "Landmarks",
    "LandmarkParams",
    "BatchItem",
    "Camera",
    "DEFAULT_OBJECT_DIAMETER",
    "FrameSource",
    "HammerParams",
    "HammerMVError",
    "InputError",
    "PlanningError",
    "TrackingError",
    "MarkerSet",
    "ModelSpec",
    "MotorModel",
    "MovementRecord",
    "MovementSpan",
    "Observation",
    "ObserveParams",
    "Recognition",
    "OnlineRecognizer",
    "RecognitionSettings",
    "RenderStyle",
    "Repertoire",
    "Scene",
    "SceneSpec",
    "SettleRule",
    "StepScorer",
    "VerdictRules",
    "judge",
    "open_source",
    "SimilarityTransform",
    "Status",
    "Tracker",
    "TrackerParams",
    "Tracks",
    "TracksWriter",
    "default_markers",
    "demo_tracks",
    "discover",
    "load_clip",
    "load_movements",
    "movement_record",
    "recognize_reach",
    "read_reaches",
    "landmarks",
    "load_recipe",
    "movement_span",
    "observe",
    "open_video",
    "recognize",
    "recognize_clip",
    "render_clip",
    "run_batch",
    "synthesize",
    "track_video",
    "write_batch_report",
    "write_clip_report",
    "write_video",
]
