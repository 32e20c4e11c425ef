"""Build the optional compiled kernels: the forward solver's (undamped and complex modes) and the Whittle
fit's linear terms (spectra).

Everything else is declared in pyproject.toml. The extension is optional:
without a C compiler the install still succeeds and the solver and the fits run
on their numpy paths (same numerics, slower for small problems).

The forward kernels include the segment dynamic stiffness and its assembly from one
source written over the scalar type (``_segment.h``: real ω, complex ω), and
the problem layout from ``_problem.h``; ``depends`` rebuilds them when a
header changes and puts the headers in the sdist.
"""

from setuptools import Extension, setup

HEADERS = ["stcs_ident/forward/_problem.h", "stcs_ident/forward/_segment.h"]

setup(
    ext_modules=[
        Extension(
            "stcs_ident.forward._dsm_kernel",
            sources=["stcs_ident/forward/_dsm_kernel.c"],
            depends=HEADERS,
            extra_compile_args=["-O2"],
            optional=True,
        ),
        Extension(
            "stcs_ident.forward._damped_kernel",
            sources=["stcs_ident/forward/_damped_kernel.c"],
            depends=HEADERS,
            extra_compile_args=["-O2"],
            optional=True,
        ),
        Extension(
            "stcs_ident.spectra._whittle_kernel",
            sources=["stcs_ident/spectra/_whittle_kernel.c"],
            extra_compile_args=["-O2"],
            optional=True,
        ),
    ]
)
