"""The thesis's figures and quantitative claims, reproduced: ``python -m tools.thesis``.

Each chapter is a module that measures (``ch2``, ``ch3``, ``appendix_a``, ``ch4``,
``ch5``, with their helpers) and a table of its claims as data (``*_claims``:
:class:`tools.thesis.claims.Claim`); :func:`tools.thesis.claims.evaluate` checks
every claim the same way; :mod:`tools.thesis.markdown` writes numbers.md and
:mod:`tools.thesis.cli` runs the chapters (``tools/reproduce_thesis.py``).
"""
