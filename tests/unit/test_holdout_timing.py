"""The held-out check's cost ratio (suspsim.convergence.holdout): paid CPU over the cheapest run
meeting the tolerance, and the best-of-two re-timing that keeps one slow timing from failing it."""
import math
from types import SimpleNamespace

from suspsim.convergence import holdout


def _record(width, error, cpu):
    return {"width": width, "error": error, "error_stderr": 0.0, "cpu_time": cpu}


def test_ratio_is_paid_over_cheapest_meeting_run():
    records = [_record(4, 0.05, 3.0), _record(5, 0.04, 1.0), _record(3, 0.2, 0.5)]
    paid, ratio, best = holdout._ratio(records, 1, tolerance=0.1)
    assert (paid, ratio, best) == (3.0, 3.0, 1)
    paid, ratio, best = holdout._ratio(records, 1, tolerance=0.01)
    assert math.isnan(ratio) and best == -1


def test_retime_keeps_the_smaller_cpu_time(monkeypatch):
    case = SimpleNamespace(settings=lambda: {"width": 0})
    again = {4: 2.0, 5: 1.5}
    monkeypatch.setattr(holdout, "_measure",
                        lambda case, settings: {"cpu_time": again[settings["width"]]})
    records = [_record(4, 0.05, 3.0), _record(5, 0.04, 1.0)]
    holdout._retime(case, records, [0, 1])
    assert [r["cpu_time"] for r in records] == [2.0, 1.0]
