"""The numerical platform of a test run: what sets the last bits of floating-point
results that an optimiser, a sampler or a long simulation can amplify.

numpy dispatches its loops (exp, log, sums) to the processor's vector instructions, and
its AVX2 and AVX-512 code differ in the last ulp; the BLAS picks a kernel per processor;
numba compiles for the host processor (fused multiply-adds where it has them); and the
numerical libraries change their arithmetic between versions. A result recorded bit for
bit is therefore recorded for one platform (:func:`platform_fingerprint`), and a test on
another platform checks what does not depend on the last bits.
"""

from __future__ import annotations

import hashlib
import json
import platform

__all__ = ["NUMERICAL_LIBRARIES", "SIMD_FEATURES", "platform_fingerprint", "platform_info"]

#: The numerical libraries whose versions are part of the platform.
NUMERICAL_LIBRARIES = ("numpy", "scipy", "numba", "llvmlite", "emcee", "pandas", "xarray", "arviz")
#: numpy's processor features that change which vector code its loops run.
SIMD_FEATURES = (
    "SSE42", "AVX", "AVX2", "FMA3", "AVX512F", "AVX512_SKX", "AVX512_ICL", "AVX512_SPR",
    "ASIMD", "SVE", "VSX", "VX",
)  # fmt: skip


def platform_info() -> dict:
    """What sets the last bits of a run's arithmetic (see the module docstring):
    the machine, numpy's vector features, the BLAS kernel, numba's target processor and
    the numerical libraries' versions."""
    from importlib.metadata import version

    import llvmlite.binding as llvm
    import scipy.linalg  # noqa: F401  (its own BLAS, loaded before it is listed)
    import threadpoolctl

    try:
        from numpy._core._multiarray_umath import __cpu_features__ as features
    except ImportError:  # numpy < 2
        from numpy.core._multiarray_umath import __cpu_features__ as features
    blas = [
        f"{i.get('internal_api')} {i.get('architecture')} {i.get('version')}"
        for i in threadpoolctl.threadpool_info()
        if i.get("user_api") == "blas"
    ]
    return {
        "machine": platform.machine(),
        "python": ".".join(platform.python_version_tuple()[:2]),
        "simd": sorted(k for k in SIMD_FEATURES if features.get(k)),
        "blas": sorted(blas),
        "numba_cpu": llvm.get_host_cpu_name(),
        "versions": {name: version(name) for name in NUMERICAL_LIBRARIES},
    }


def platform_fingerprint(info: dict) -> str:
    """A short hash of :func:`platform_info`'s record: the key of a platform's values."""
    text = json.dumps(info, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:12]
