"""Rigid bodies: shapes and packings (SPEC §4).

- :mod:`~suspsim.bodies.harmonics`: real spherical harmonics — stable recurrence, synthesis
  and exact projection on Gauss grids, compiled point evaluation, exact rotation;
- :mod:`~suspsim.bodies.shapes`: star-shaped bodies r(θ, φ) = Σ a_nm Y_nm — volume, centroid,
  inertia, support radius, point-in-body test, normals and principal curvatures;
- :mod:`~suspsim.bodies.grains`: random realistic sand grains (Garboczi 2002);
- :mod:`~suspsim.bodies.sizes`: truncated lognormal sizes and the exact-φ rescaling;
- :mod:`~suspsim.bodies.rotations`: quaternions, uniform random orientations;
- :mod:`~suspsim.bodies.pairs`: cell list and minimum image for candidate body pairs;
- :mod:`~suspsim.bodies.radius_table`: cube-map tables of r(u) for fast lookups;
- :mod:`~suspsim.bodies.relax`: overlap removal by soft repulsion and FIRE;
- :mod:`~suspsim.bodies.overlap`: exact overlap checks (sphere gaps, dense grain sampling);
- :mod:`~suspsim.bodies.construction`: bodies as rigid shells of SPH particles (SPEC §3.1);
- :mod:`~suspsim.bodies.rigid`: NO_SQUISH symplectic rotation of rigid bodies (SPEC §3.2);
- :mod:`~suspsim.bodies.lubrication`, :mod:`~suspsim.bodies.lubrication_implicit`: pair
  lubrication (Jeffrey–Onishi, correction form), repulsion, curved squeeze, implicit impulses
  (SPEC §3.3–3.4);
- :mod:`~suspsim.bodies.packing`: :func:`~suspsim.bodies.packing.pack_spheres`,
  :func:`~suspsim.bodies.packing.pack_sand` and the :class:`~suspsim.bodies.packing.Packing`
  they return (stored by :mod:`suspsim.io.packing_file`).

Lengths are in [length] = h, the SPH kernel support radius.
"""
