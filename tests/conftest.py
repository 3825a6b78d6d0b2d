"""Test-session settings shared by every test module."""
import os

# Under pytest-xdist each core runs its own worker process, so a worker's numba pool gets one
# thread (the solvers clamp their requested threads to it). Two workers with two numba threads
# each oversubscribe the two cores, and numba's workers then wait for each other at every
# parallel pass: the reduced slow suite took longer on two such workers than on one process.
# Set before the first import of numba.
if os.environ.get("PYTEST_XDIST_WORKER"):
    os.environ.setdefault("NUMBA_NUM_THREADS", "1")

# Shared fixtures are session-scoped, not module-scoped: with --dist loadgroup a worker runs the
# tests of several modules interleaved, and a module fixture is torn down whenever the worker
# leaves its module. Tests that share an expensive fixture also carry one xdist_group mark, so
# that one worker builds it once (that needs pytest < 9: see pyproject.toml).
