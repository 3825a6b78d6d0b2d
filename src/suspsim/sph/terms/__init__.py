"""Physics terms of the SPH fluid (SPEC §2.2–2.5, §2.8) and the pair passes that apply them.

Each term is a small ``@njit`` function of named scalars (equation and source in its docstring),
inlined into the compiled pair passes:

- :mod:`.pressure`: equation of state and the pressure pair force (SPEC §2.2);
- :mod:`.viscous`: the viscous pair force A + symmetrised B^c and the explicit ∇a term
  (SPEC §2.3–2.4);
- :mod:`.gradient`: moment matrix, corrected velocity gradient, shear rate (SPEC §2.5);
- :mod:`.normalisation`: the dissipation normalisation factor (SPEC §2.3, "What the probe found");
- :mod:`.velocity_pass`: the gradient/shear-rate pass and the normalisation pass;
- :mod:`.force_pass`: pressure + viscous forces + stress virial in one pass.

Step order (``integrator``): density pass (``density``, writes the pair table) → velocity
gradient pass (γ̇, μ) → normalisation pass (μ̂ = μ/s) → force pass. Scenes skip what they do not
need: a Newtonian fluid without the normalisation runs density and force passes only.
"""
