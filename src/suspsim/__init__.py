"""suspsim: viscosity of suspensions in non-Newtonian matrix fluids by SPH, from rheometry to figures."""
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("suspsim")
except PackageNotFoundError:
    __version__ = "0+unknown"
