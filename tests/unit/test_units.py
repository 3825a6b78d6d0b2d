"""Physical ↔ simulation units (SPEC §7): the dimensionless law is kept, Re is the target."""
import math

import numpy as np
import pytest

from suspsim.errors import InputError
from suspsim.rheology.laws import LAW_SPECS, make_law
from suspsim.units import (MAX_REYNOLDS, SIMULATION_SHEAR_RATE, UNIT_POWERS, convert_parameter,
                           unit_mapping)

#: One physically sensible parameter set per law (SI), regularisations inside the rate range.
LAWS = {
    "newtonian": {"mu": 0.35},
    "power_law": {"K": 3.0, "n": 0.4, "gdot_min": 1e-4},
    "cross": {"mu_0": 50.0, "mu_inf": 0.02, "lam": 2.5, "m": 0.8},
    "carreau_yasuda": {"mu_0": 2.1, "mu_inf": 1e-3, "lam": 0.1, "a": 0.86, "n": 0.3},
    "papanastasiou": {"mu_pl": 0.5, "mu_0": 40.0, "M": 20.0},
    "herschel_bulkley": {"tau_y": 20.0, "K": 8.0, "n": 0.55, "M": 300.0, "gdot_min": 1e-5},
    "three_component": {"tau_y": 20.8, "gdot_c": 0.95, "eta_bg": 0.72, "M": 1e3},
}
PHYSICAL_RATES = (1e-3, 0.7, 1e3)
PROBE_RATES = np.geomspace(1e-5, 1e5, 61)
DENSITY = 4.096


def test_every_law_has_a_parameter_set_here():
    assert set(LAWS) == set(LAW_SPECS)


@pytest.mark.parametrize("rate", PHYSICAL_RATES)
@pytest.mark.parametrize("name", sorted(LAWS))
def test_simulated_law_times_viscosity_scale_is_the_physical_law(name, rate):
    """μ_sim(T γ̇') S_μ = μ(γ̇') and S_σ σ_sim(T γ̇') = σ(γ̇'), far beyond the mapped rate too."""
    law = make_law(name, LAWS[name])
    mapping = unit_mapping(law, rate, density=DENSITY)
    sim = mapping.law_to_simulation(law)
    assert sim.name == name and set(sim.params) == set(law.params)
    sim_rates = mapping.rate_to_simulation(PROBE_RATES)
    assert np.allclose(mapping.viscosity_to_physical(sim.viscosity(sim_rates)),
                       law.viscosity(PROBE_RATES), rtol=1e-11, atol=0)
    assert np.allclose(mapping.stress_to_physical(sim.stress(sim_rates)),
                       law.stress(PROBE_RATES), rtol=1e-11, atol=0)


@pytest.mark.parametrize("name", sorted(LAWS))
def test_particle_reynolds_number_is_the_target(name):
    law = make_law(name, LAWS[name])
    for reynolds in (1e-3, 0.05, MAX_REYNOLDS):
        for length in (1.0, 2.5):
            m = unit_mapping(law, 3.0, density=DENSITY, reynolds_number=reynolds,
                             reynolds_length=length)
            mu_sim = float(m.law_to_simulation(law).viscosity(m.simulation_shear_rate))
            assert DENSITY * length ** 2 * m.simulation_shear_rate / mu_sim == pytest.approx(
                reynolds, rel=1e-12)
            assert m.simulation_shear_rate == SIMULATION_SHEAR_RATE
            assert float(m.rate_to_simulation(3.0)) == pytest.approx(SIMULATION_SHEAR_RATE)


def test_scales_follow_their_definitions():
    law = make_law("newtonian", {"mu": 2.0})
    m = unit_mapping(law, 50.0, density=4.0, reynolds_number=0.1, simulation_shear_rate=0.01)
    assert m.time_scale == pytest.approx(0.01 / 50.0)
    assert m.viscosity_scale == pytest.approx(2.0 * 0.1 / (4.0 * 0.01))
    assert m.stress_scale == pytest.approx(m.viscosity_scale / m.time_scale)
    assert float(m.time_to_physical(100.0)) == pytest.approx(100.0 * m.time_scale)
    assert m.matrix_viscosity == 2.0


def test_parameter_conversion_by_unit():
    """Each declared unit Pa^a s^b divides by S_σ^a T^b; K in Pa s^n by S_μ T^(n−1)."""
    T, S = 0.02, 7.0
    assert convert_parameter(3.0, "Pa s", T, S) == pytest.approx(3.0 / S)
    assert convert_parameter(3.0, "s", T, S) == pytest.approx(3.0 / T)
    assert convert_parameter(3.0, "1/s", T, S) == pytest.approx(3.0 * T)
    assert convert_parameter(3.0, "Pa", T, S) == pytest.approx(3.0 * T / S)
    assert convert_parameter(3.0, "Pa s^n", T, S, flow_index=0.4) == pytest.approx(
        3.0 / (S * T ** (0.4 - 1)))
    assert convert_parameter(3.0, "1", T, S) == 3.0
    declared = {p.unit for spec in LAW_SPECS.values() for p in spec.parameters}
    assert declared <= set(UNIT_POWERS)
    with pytest.raises(ValueError, match="furlong"):
        convert_parameter(1.0, "furlong", T, S)
    with pytest.raises(ValueError, match="flow index"):
        convert_parameter(1.0, "Pa s^n", T, S)


def test_mapping_attributes_are_finite_numbers_and_carry_mach_once_known():
    law = make_law("cross", LAWS["cross"])
    m = unit_mapping(law, 1.0, density=DENSITY)
    attrs = m.to_attributes()
    assert "unit_mach_number" not in attrs and "unit_length_scale_m_per_h" not in attrs
    assert all(isinstance(v, float) and math.isfinite(v) for v in attrs.values())
    assert attrs["unit_particle_reynolds_number"] == pytest.approx(0.1)
    later = m.with_mach(0.02).to_attributes()
    assert later["unit_mach_number"] == 0.02


def test_length_scale_from_a_physical_particle_size():
    law = make_law("newtonian", {"mu": 1.0})
    m = unit_mapping(law, 1.0, density=DENSITY, particle_size=50e-6, particle_radius=2.5,
                     reynolds_length=2.5)
    assert m.length_scale == pytest.approx(2e-5)
    assert float(m.length_to_physical(2.5)) == pytest.approx(50e-6)
    without = unit_mapping(law, 1.0, density=DENSITY)
    with pytest.raises(InputError, match="length scale"):
        without.length_to_physical(1.0)
    with pytest.raises(InputError, match="both"):
        unit_mapping(law, 1.0, density=DENSITY, particle_size=50e-6)


@pytest.mark.parametrize("kwargs, match", [
    ({"reynolds_number": 0.2}, "exceeds"),
    ({"reynolds_number": 0.0}, "reynolds_number"),
    ({"density": -1.0}, "density"),
    ({"simulation_shear_rate": math.nan}, "simulation_shear_rate"),
])
def test_bad_mapping_inputs_are_input_errors(kwargs, match):
    law = make_law("newtonian", {"mu": 1.0})
    with pytest.raises(InputError, match=match):
        unit_mapping(law, 1.0, **{"density": DENSITY, **kwargs})
    with pytest.raises(InputError, match="shear_rate"):
        unit_mapping(law, 0.0, density=DENSITY)
