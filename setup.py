"""Build the optional compiled kernels of the forward solver (undamped and complex modes).

Everything else is declared in pyproject.toml. The extension is optional:
without a C compiler the install still succeeds and the solver runs on its
numpy path (same numerics, slower for small problems).

Both kernels include the segment dynamic stiffness and its assembly from one
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
    ]
)
