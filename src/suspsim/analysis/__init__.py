"""Statistics of simulation output: means and standard errors of correlated time series."""
from .blocking import MeanEstimate, batch_means, blocking_mean, periodic_batch_means

__all__ = ["MeanEstimate", "batch_means", "blocking_mean", "periodic_batch_means"]
