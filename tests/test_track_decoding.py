"""track_video decodes ahead while it opens the tracks file (issue 45 item 5).

The decoding thread sets tracking's pace: the tracks file (h5py's import,
23 ms) is opened once it has started, and it reads ahead as many frames as
fit in 32 MiB, so that the tracker's first detection does not stop it.
"""

from __future__ import annotations

from perception.io import video
from perception.io.tracks import Tracks, TracksWriter
from perception.synthetic.render import render_clip
from perception.synthetic.scene import Camera, RenderStyle, Scene
from perception.tracking.video_tracks import track_video


def _clip(path, n=12):
    scene = Scene.reach_to_grasp(n, 30.0, onset=0.1, duration=0.2)
    return render_clip(scene, Camera.for_frame(160, 120), RenderStyle(fps=30.0), path, seed=1)


def test_the_tracks_file_opens_while_frames_are_decoded(tmp_path, monkeypatch):
    clip = _clip(tmp_path / "clip.mp4")
    seen, sources = [], []
    enter, init = TracksWriter.__enter__, video.FrameSource.__init__

    def entered(self):
        # the decoding thread has started (a 12-frame clip may be decoded whole already:
        # whether it is still alive is the scheduler's, not the test's)
        ahead = sources[0]._ahead if sources else None
        seen.append(ahead is not None and ahead._thread.name == "decode:clip.mp4"
                    and ahead._thread.ident is not None)
        return enter(self)

    def opened(self, *args, **kwargs):
        init(self, *args, **kwargs)
        sources.append(self)

    monkeypatch.setattr(TracksWriter, "__enter__", entered)
    monkeypatch.setattr(video.FrameSource, "__init__", opened)
    out = track_video(clip.video, tmp_path / "clip.tracks.h5")
    assert seen == [True]
    assert sources[0].prefetch == 32  # 160 x 120 frames: the most read ahead
    assert Tracks.load(out).n_frames == 12
