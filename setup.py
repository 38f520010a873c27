"""Build step of hammer-mv: the compiled passes of minvar's LQG solver.

Everything else is in pyproject.toml. The extension module minvar._lqg_kernel
(minvar/_lqg_kernel.c, plain C against Python's own headers: no numpy headers
needed) is optional: without a C compiler the install goes on, and the solver
uses its numpy passes with the same results, five to ten times slower; the
first solve says so in a warning (docs/model.md, "The compiled kernel").
"""

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext


class BuildExt(build_ext):
    """build_ext with the optimisation flag each compiler understands."""

    def build_extensions(self):
        # MSVC optimises release builds already and warns on -O3
        if self.compiler.compiler_type != "msvc":
            for ext in self.extensions:
                ext.extra_compile_args = [*ext.extra_compile_args, "-O3"]
        super().build_extensions()


setup(
    ext_modules=[Extension("minvar._lqg_kernel", ["minvar/_lqg_kernel.c"], optional=True)],
    cmdclass={"build_ext": BuildExt},
)
