"""suspsim: viscosity of suspensions in non-Newtonian matrix fluids by SPH, from rheometry to figures."""
from importlib.metadata import PackageNotFoundError, version

from suspsim.jit_cache import use_source_cache

# Before any compiled function is defined: numba reads its cache folder at decoration.
use_source_cache()

try:
    __version__ = version("suspsim")
except PackageNotFoundError:
    __version__ = "0+unknown"
