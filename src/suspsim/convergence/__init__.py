"""The speed-against-error study (issue 7): validation cases swept over their numerical
settings, each configuration's error against the exact reference and its wall time."""
