"""Test-session settings shared by every test module."""
import os

# Under pytest-xdist each core runs its own worker process, so a worker's numba pool gets one
# thread (the solvers clamp their requested threads to it). Two workers with two numba threads
# each oversubscribe the two cores, and numba's workers then wait for each other at every
# parallel pass: the reduced slow suite took longer on two such workers than on one process.
# Set before the first import of numba.
if os.environ.get("PYTEST_XDIST_WORKER"):
    os.environ.setdefault("NUMBA_NUM_THREADS", "1")
