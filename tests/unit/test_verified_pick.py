"""The verified tolerance picker (suspsim.convergence.picker.verified_pick): runs candidates
until a measured error meets the tolerance, recalibrating the model on each miss. The runs here
are stand-ins whose measured error is a known multiple of the model's, so what each attempt
must be is known exactly."""
import math

import pytest

from suspsim.convergence import error_model as em
from suspsim.convergence import picker as pk
from suspsim.convergence.cases import get_case
from suspsim.errors import InputError

CASE = "couette_newtonian_3d"


@pytest.fixture(scope="module")
def rows():
    """(settings, drivers, uninflated model error, expected cost), cheapest first."""
    model = em.load_model()
    return sorted(((s, d, sum(model.terms(d).values()), c)
                   for s, d, _, c in pk.evaluate(get_case(CASE), model)), key=lambda r: r[3])


def runner(factor, blow_up_above=math.inf, log=None):
    """A run whose measured bound is ``factor`` × the model error; inf (a blow-up) where
    C_Δx ≥ ``blow_up_above``; CPU time = the model's expected cost."""
    model = em.load_model()
    case = get_case(CASE)

    def run(settings):
        d = em.drivers(case.build(settings), settings)
        if log is not None:
            log.append(d)
        measured = math.inf if d.courant >= blow_up_above else factor * sum(
            model.terms(d).values())
        return measured, model.expected_cost(d), None
    return run


def cheapest(rows, limit, courant_cap=math.inf):
    return next(r for r in rows if r[2] <= limit and r[1].courant < courant_cap)


def test_a_model_that_over_predicts_takes_one_run(rows):
    attempts = pk.verified_pick(get_case(CASE), 0.05, runner(0.6))
    assert len(attempts) == 1
    assert attempts[0].settings == cheapest(rows, 0.05)[0]
    assert attempts[0].measured <= 0.05


@pytest.mark.parametrize("position", [0.2, 0.8])
def test_an_under_predicting_model_is_calibrated_by_its_first_miss(rows, position):
    """Measured = k E, with k between ε/E_first (the first run, E ≤ ε, misses) and ε/E_min
    (some candidate still meets): the first miss's ratio k then picks the cheapest candidate
    with k E ≤ ε, which meets, as a model inflated by k would have."""
    first = cheapest(rows, 0.05)
    smallest = min(r[2] for r in rows)
    factor = (0.05 / first[2]) ** (1 - position) * (0.05 / smallest) ** position
    attempts = pk.verified_pick(get_case(CASE), 0.05, runner(factor))
    assert attempts[0].settings == first[0]
    assert attempts[0].measured > 0.05
    assert len(attempts) == 2
    assert attempts[1].calibration == pytest.approx(factor)
    assert attempts[1].settings == cheapest(rows, 0.05 / factor)[0]
    assert attempts[1].measured <= 0.05


def test_a_blow_up_caps_the_time_step_of_the_next_attempt(rows):
    first = cheapest(rows, 0.05)
    seen = []
    attempts = pk.verified_pick(get_case(CASE), 0.05,
                                runner(0.6, blow_up_above=first[1].courant, log=seen))
    assert attempts[0].blew_up
    assert len(attempts) == 2
    assert seen[1].courant < first[1].courant
    assert attempts[1].settings == cheapest(rows, 0.05, first[1].courant)[0]
    assert attempts[1].record()["measured_error"] <= 0.05
    assert attempts[0].record()["measured_error"] is None


def test_every_miss_names_the_attempts():
    with pytest.raises(InputError, match="not met.*measured.*calibration"):
        pk.verified_pick(get_case(CASE), 0.05, runner(1e3))
    with pytest.raises(InputError, match="not met.*blew up"):
        pk.verified_pick(get_case(CASE), 0.05, runner(0.5, blow_up_above=0.0))
    with pytest.raises(InputError, match="relative error in"):
        pk.verified_pick(get_case(CASE), 1.5, runner(1.0))


def test_attempts_grow_dearer_and_stop_at_the_cap():
    with pytest.raises(InputError, match=r"not met \([^;()]* measured\); the smallest"):
        pk.verified_pick(get_case(CASE), 0.05, runner(1e3), max_attempts=1)
    model = em.load_model()
    costs = [model.expected_cost(a.drivers) for a in
             pk.verified_pick(get_case(CASE), 0.02, runner(2.0))]
    assert costs == sorted(costs)
