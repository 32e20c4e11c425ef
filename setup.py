"""Build the optional compiled kernels of the forward solver (undamped and complex modes).

Everything else is declared in pyproject.toml. The extension is optional:
without a C compiler the install still succeeds and the solver runs on its
numpy path (same numerics, slower for small problems).
"""

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension(
            "stcs_ident.forward._dsm_kernel",
            sources=["stcs_ident/forward/_dsm_kernel.c"],
            extra_compile_args=["-O2"],
            optional=True,
        ),
        Extension(
            "stcs_ident.forward._damped_kernel",
            sources=["stcs_ident/forward/_damped_kernel.c"],
            extra_compile_args=["-O2"],
            optional=True,
        ),
    ]
)
