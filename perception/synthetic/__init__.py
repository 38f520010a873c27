"""Synthetic clips: scenes, the renderer, the chapter 5 stimuli, recipes and ready-made demos.

* :mod:`~perception.synthetic.scene` — what a clip shows (scene, camera, style);
* :mod:`~perception.synthetic.render` — drawing frames and writing clips with ground truth;
* :mod:`~perception.synthetic.stimuli` — normal, delayed and open-close-open grasps;
* :mod:`~perception.synthetic.recipes` — sets of clips from a TOML recipe;
* :mod:`~perception.synthetic.demos` — demonstrations for tests and benchmarks.
"""
