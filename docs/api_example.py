"""fegear from Python: the FZG spur pair, loaded, as designed and with a tilted gear axis."""

import fegear

case = fegear.load_case("cases/fzg_spur.toml")  # a case file (TOML, units in the keys)
tilted = case.with_errors(f_sigma_beta_mm=0.01)  # a new, validated case: 10 µm axis tilt

for name, c in {"as designed": case, "tilted": tilted}.items():
    r = fegear.run(c, fidelity="hybrid", level=0)  # loaded TCA over one mesh cycle
    cy = r.cycle  # the headline numbers of summary.json (None, with a reason, if not reported)
    print(f"{name}: TE p-p {cy.te_pp_loaded_arcsec:.2f} arcsec, p_max {cy.p_max_MPa:.0f} MPa, "
          f"loaded contact ratio {cy.contact_ratio_loaded:.2f}")  # fmt: skip

for p in r.positions:  # the last run, position by position
    shares = " ".join(f"{q.load_share:.2f}" for q in p.pairs if q.in_contact)
    print(f"phi1 {p.pinion_angle_deg:6.2f} deg  TE {p.te_loaded_arcsec:7.2f} arcsec  "
          f"load shares {shares}")  # fmt: skip

pc = r.pattern["gear"]  # where the bearing pattern is on the gear flank (flank coordinates)
print(f"pattern centre: {pc.face_name} {pc.face_mm:+.2f}, {pc.profile_name} {pc.profile_mm:.2f}")
r.write("out/fzg_tilted")  # summary.json, cycle.pvd + vtk/, PNGs: the files of `fegear run`
r.plot_pattern("out/fzg_tilted/gear_flank.png")  # the bearing pattern on the gear flank
