"""Build step of hammer-mv: the compiled passes of minvar's LQG solver.

Everything else is in pyproject.toml. The extension is optional: without a C
compiler the install goes on and the solver uses its numpy passes
(minvar/_kernel.py), with the same results, several times slower.
"""

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension(
            "minvar._lqg_kernel",
            ["minvar/_lqg_kernel.c"],
            extra_compile_args=["-O3"],
            optional=True,
        )
    ]
)
