"""Speed benchmark of the SPH bead model: ``make bench`` (``python -m beadsim.bench``).

Prints, from one run on this machine:

1. throughput: particle-steps per second of a short moving-window run of mode 1 on 1 and 2 MPI ranks (median of
   ``--repeats``), and the share of wall time spent outside LAMMPS (Python between chunks, 1 rank);
1b. the ``fluid_pairs_only`` lever on and off on a scene with melt (mode 2 at ``--dx`` for ``--lever-time``):
   particle-steps per second of each, their ratio and what the lever changes in the pool;
2. each Table 4 mode with every speed lever on (moving window, steady-state stop, 2 ranks) at ``--dx``: wall time,
   particles, steps, steady-state time, bead width and height and their error against Table 1;
3. the paper's whole plate for its full 2 s at ``--dx``: measured per-particle-step cost of a short whole-plate
   run times the particle-steps of the full run (an estimate, said so in the output) -- or the real run with
   ``--full-plate``;
4. a same-physics comparison at ``--ref-dx`` (coarser, so that the whole-plate run for the full 2 s is affordable):
   bead width and height of the whole plate and of the moving window with the levers, their difference and the
   wall-time ratio.

Everything goes to ``--out`` (default ``results/bench``): one folder per run, ``bench.json`` (all figures) and
``speed_accuracy.png`` (wall time against the error versus Table 1 and versus the whole plate). Runs whose
``result.json`` already holds the same parameters are not repeated unless ``--fresh``.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import statistics
import time
from pathlib import Path

from beadsim import __version__
from beadsim.io import write_json
from beadsim.parameters import defaults
from beadsim.provenance import provenance
from beadsim.runner import run_case
from beadsim.study import load_experiments

log = logging.getLogger("beadsim.bench")

LEVERS = {"domain": "window", "stop_at_steady_state": True}


#: The production physics and scene settings of the table4_sph study (the same in every bench run, so that
#: comparisons are fair): melt conductivity x5, window margin 4 thermal lengths (mode 2 melts past the side faces
#: at 3), wire feed started on the pool (mode 3 stubs when fed from t = 0).
PHYSICS = {"melt_conductivity_factor": 5.0, "window_thermal_lengths": 4.0, "wire_feed_start": "pool"}


def mode_params(mode: int, **overrides) -> dict:
    """Parameters of Table 4 mode ``mode`` with the SPH model, the production physics and ``overrides``."""
    p = defaults()
    p["model"] = "sph"
    p.update(PHYSICS)
    row = load_experiments().loc[mode]
    for key, value in row.items():
        if key in p:
            p[key] = value.item() if hasattr(value, "item") else value
    p.update(overrides)
    return p


def run(params: dict, outdir: Path, tasks: int, fresh: bool) -> dict:
    """Run one case (or reuse its result when the parameters match); return the result record."""
    result = outdir / "result.json"
    if not fresh and result.exists() and (outdir / "params.json").exists():
        if json.loads((outdir / "params.json").read_text()) == params:
            return json.loads(result.read_text())
    outdir.mkdir(parents=True, exist_ok=True)
    write_json(outdir / "params.json", params)
    t0 = time.perf_counter()
    record = run_case(params, outdir, run_id=outdir.name, tasks=tasks)
    record["bench_wall_s"] = time.perf_counter() - t0
    write_json(result, record)
    status = record["status"] + (f" ({record['reason']})" if record["reason"] else "")
    print(f"  {outdir.name}: {status}, {record['bench_wall_s']:.0f} s", flush=True)
    return record


def rel(a: float, b: float) -> float:
    """Relative difference a / b - 1 (NaN when undefined)."""
    try:
        return a / b - 1 if b else math.nan
    except TypeError:
        return math.nan


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(prog="python -m beadsim.bench", description=__doc__.split("\n\n")[0])
    ap.add_argument("--dx", type=float, default=0.2, help="resolution of the per-mode runs, mm (default 0.2)")
    ap.add_argument("--modes", type=int, nargs="+", default=[1, 2, 3], help="Table 4 modes (default 1 2 3)")
    ap.add_argument("--ranks", type=int, default=2, help="MPI ranks per run with the levers (default 2)")
    ap.add_argument("--repeats", type=int, default=3, help="repeats of the throughput runs (default 3)")
    ap.add_argument("--throughput-time", type=float, default=0.02, help="process time of a throughput run, s")
    ap.add_argument("--lever-time", type=float, default=0.2,
                    help="process time of the fluid-pairs lever runs (mode 2 at --dx, with melt), s")
    ap.add_argument("--ref-dx", type=float, default=0.4, help="resolution of the whole-plate comparison, mm")
    ap.add_argument("--full-plate", action="store_true", help="run the whole plate at --dx for 2 s (hours)")
    ap.add_argument("--skip", nargs="*", default=[], choices=["throughput", "levers", "modes", "plate", "reference"])
    ap.add_argument("--fresh", action="store_true", help="repeat runs that already have results")
    ap.add_argument("--out", type=Path, default=Path("results/bench"))
    args = ap.parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    out = args.out
    exp = load_experiments()
    report: dict = {"args": {k: (str(v) if isinstance(v, Path) else v) for k, v in vars(args).items()},
                    "provenance": provenance(with_lammps=True), "beadsim_version": __version__}

    # 1. throughput on 1 and 2 ranks
    if "throughput" not in args.skip:
        print(f"[1] throughput: mode 1, moving window, dx {args.dx} mm, {args.throughput_time} s of process, "
              f"{args.repeats} repeats on 1 and {args.ranks} ranks", flush=True)
        tp = {}
        for ranks in sorted({1, args.ranks}):
            recs = [run(mode_params(1, domain="window", resolution_mm=args.dx, sim_time_s=args.throughput_time,
                                    restart_interval_s=60.0, dump_interval_s=60.0),
                        out / f"throughput_r{ranks}_{i}", ranks, args.fresh or i > 0)
                    for i in range(args.repeats)]
            ok = [r["metrics"] for r in recs if r["status"] == "ok"]
            tp[ranks] = {"particle_steps_per_s": statistics.median(m["particle_steps_per_s"] for m in ok),
                         "python_time_share": statistics.median(m["python_time_share"] for m in ok),
                         "n_particles": ok[0]["n_particles"], "n_steps": ok[0]["n_steps"], "runs": len(ok)}
        report["throughput"] = tp
        for ranks, v in tp.items():
            print(f"    {ranks} rank(s): {v['particle_steps_per_s'] / 1e6:.3f} M particle-steps/s (median of "
                  f"{v['runs']}, {v['n_particles']} particles x {v['n_steps']} steps incl. set-up), time outside "
                  f"LAMMPS {v['python_time_share']:.1%}")
        if len(tp) > 1:
            print(f"    speed-up {args.ranks} ranks / 1 rank: "
                  f"{tp[args.ranks]['particle_steps_per_s'] / tp[1]['particle_steps_per_s']:.2f}")

    # 1b. the fluid-pairs lever, on a scene with melt (the throughput runs above end before the pool forms)
    if "levers" not in args.skip:
        print(f"[1b] lever fluid_pairs_only: mode 2, moving window, dx {args.dx} mm, {args.lever_time} s of process "
              f"(the pool is forming), {args.ranks} ranks, lever on and off", flush=True)
        lev = {}
        for on in (True, False):
            rec = run(mode_params(2, domain="window", resolution_mm=args.dx, sim_time_s=args.lever_time,
                                  fluid_pairs_only=on, restart_interval_s=60.0, dump_interval_s=60.0),
                      out / f"lever_fpo_{'on' if on else 'off'}_dx{args.dx}", args.ranks, args.fresh)
            m = rec["metrics"]
            lev["on" if on else "off"] = {
                "status": rec["status"], "reason": rec["reason"], "wall_s": rec["elapsed_s"],
                "particle_steps_per_s": m.get("particle_steps_per_s"), "n_particles": m.get("n_particles"),
                "n_steps": m.get("n_steps"), "simulated_time_s": m.get("simulated_time_s"),
                "python_time_share": m.get("python_time_share"), "pool_volume_mm3": m.get("pool_volume_mm3"),
                "boundary_heat_loss_J": m.get("boundary_heat_loss_J")}
        report["levers"] = lev
        for key, v in lev.items():
            print(f"    fluid pairs only {key:>3}: {v['status']} {v['reason']}; "
                  f"{(v['particle_steps_per_s'] or math.nan) / 1e6:.3f} M particle-steps/s, {v['n_particles']} "
                  f"particles x {v['n_steps']} steps to t = {v['simulated_time_s']:.3g} s, time outside LAMMPS "
                  f"{(v['python_time_share'] or math.nan):.1%}, pool {(v['pool_volume_mm3'] or math.nan):.3g} mm3",
                  flush=True)
        if all(v["particle_steps_per_s"] for v in lev.values()):
            print(f"    speed-up on / off: {lev['on']['particle_steps_per_s'] / lev['off']['particle_steps_per_s']:.2f}; "
                  f"pool volume {rel(lev['on']['pool_volume_mm3'], lev['off']['pool_volume_mm3']):+.1%}, boundary "
                  f"heat loss {rel(lev['on']['boundary_heat_loss_J'], lev['off']['boundary_heat_loss_J']):+.1%}")

    # 2. every mode with all levers
    if "modes" not in args.skip:
        print(f"[2] Table 4 modes with all levers (moving window, steady-state stop, {args.ranks} ranks), "
              f"dx {args.dx} mm", flush=True)
        modes = {}
        for mode in args.modes:
            rec = run(mode_params(mode, resolution_mm=args.dx, **LEVERS), out / f"mode{mode}_dx{args.dx}",
                      args.ranks, args.fresh)
            m = rec["metrics"]
            row = exp.loc[mode]
            modes[mode] = {"status": rec["status"], "reason": rec["reason"], "wall_s": rec["elapsed_s"],
                           "n_particles": m.get("n_particles"), "n_steps": m.get("n_steps"),
                           "simulated_time_s": m.get("simulated_time_s"),
                           "steady_state_time_s": m.get("steady_state_time_s"),
                           "width_mm": m.get("bead_width_mm"), "height_mm": m.get("bead_height_mm"),
                           "width_error": rel(m.get("bead_width_mm"), row["bead_width_mm"]),
                           "height_error": rel(m.get("bead_height_mm"), row["bead_height_mm"]),
                           "mass_balance_ratio": m.get("mass_balance_ratio"),
                           "energy_balance_error": m.get("energy_balance_error"),
                           "python_time_share": m.get("python_time_share")}
            v = modes[mode]
            if v["status"] != "ok":
                print(f"    mode {mode}: failed after {v['wall_s']:.0f} s: {v['reason']}", flush=True)
                continue
            print(f"    mode {mode}: {v['status']} {v['reason']}; wall {v['wall_s']:.0f} s "
                  f"({'within' if v['wall_s'] <= 600 else 'over'} 10 min), {v['n_particles']} particles, "
                  f"{v['n_steps']} steps to t = {v['simulated_time_s']:.3g} s (steady at "
                  f"{v['steady_state_time_s']}), bead {v['width_mm']:.3g} x {v['height_mm']:.3g} mm vs Table 1 "
                  f"{row['bead_width_mm']} x {row['bead_height_mm']} ({v['width_error']:+.0%}, "
                  f"{v['height_error']:+.0%})", flush=True)
        report["modes"] = modes

    # 3. whole plate at dx for 2 s: measured per-step cost x steps (or the real run)
    if "plate" not in args.skip:
        full = args.full_plate
        t_plate = 2.0 if full else args.throughput_time
        how = "full 2 s run" if full else (f"{t_plate} s run, cost of 2 s estimated as its particle-step rate x "
                                           "the particle-steps of 2 s")
        print(f"[3] whole plate at dx {args.dx} mm: {how}", flush=True)
        rec = run(mode_params(1, domain="plate", resolution_mm=args.dx, sim_time_s=t_plate,
                              restart_interval_s=60.0 if not full else 0.25, dump_interval_s=60.0 if not full else 0.05),
                  out / f"plate_dx{args.dx}_{t_plate}s", args.ranks, args.fresh)
        m = rec["metrics"]
        if rec["status"] != "ok" and not m.get("particle_steps_per_s"):
            print(f"    whole plate failed before it measured a rate: {rec['reason']}; section skipped")
            report["plate"] = {"status": rec["status"], "reason": rec["reason"]}
            m = None
    if "plate" not in args.skip and m is not None:
        steps_2s = math.ceil(2.0 / m["dt_s"])
        wall_2s = rec["elapsed_s"] if full else m["n_particles"] * steps_2s / m["particle_steps_per_s"]
        plate = {"n_particles": m["n_particles"], "dt_s": m["dt_s"], "steps_2s": steps_2s,
                 "particle_steps_per_s": m["particle_steps_per_s"], "wall_2s_s": wall_2s, "estimated": not full}
        report["plate"] = plate
        print(f"    {plate['n_particles']} particles, dt {plate['dt_s']:.3g} s, {steps_2s} steps for 2 s, "
              f"{plate['particle_steps_per_s'] / 1e6:.3f} M particle-steps/s on {args.ranks} ranks -> "
              f"{'measured' if full else 'estimated'} {wall_2s / 60:.0f} min for 2 s")
        if "modes" in report:
            for mode, v in report["modes"].items():
                if v["status"] != "ok":
                    continue
                print(f"    mode {mode}: levers {v['wall_s']:.0f} s vs whole plate {wall_2s:.0f} s: "
                      f"{wall_2s / v['wall_s']:.1f}x faster")

    # 4. same physics, whole plate vs window, at the reference resolution
    if "reference" not in args.skip:
        print(f"[4] mode 1 at dx {args.ref_dx} mm: whole plate for 2 s vs moving window with levers "
              f"({args.ranks} ranks)", flush=True)
        ref = run(mode_params(1, domain="plate", resolution_mm=args.ref_dx, sim_time_s=2.0),
                  out / f"plate_dx{args.ref_dx}_2s", args.ranks, args.fresh)
        if ref["status"] != "ok":  # no reference, no comparison: do not spend the window run on it
            print(f"    whole plate run failed: {ref['reason']}; no comparison at dx {args.ref_dx} mm "
                  f"(try another --ref-dx)")
            report["reference"] = {"status": ref["status"], "reason": ref["reason"],
                                   "plate_wall_s": ref["elapsed_s"]}
    if "reference" not in args.skip and report.get("reference", {}).get("status") is None:
        win = run(mode_params(1, resolution_mm=args.ref_dx, **LEVERS), out / f"mode1_dx{args.ref_dx}",
                  args.ranks, args.fresh)
        a, b = ref["metrics"], win["metrics"]
        if win["status"] != "ok":
            print(f"    window run failed: {win['reason']}")
        cmp_ = {"plate_wall_s": ref["elapsed_s"], "window_wall_s": win["elapsed_s"],
                "speedup": ref["elapsed_s"] / win["elapsed_s"],
                "plate_width_mm": a.get("bead_width_mm"), "plate_height_mm": a.get("bead_height_mm"),
                "window_width_mm": b.get("bead_width_mm"), "window_height_mm": b.get("bead_height_mm"),
                "width_difference": rel(b.get("bead_width_mm"), a.get("bead_width_mm")),
                "height_difference": rel(b.get("bead_height_mm"), a.get("bead_height_mm")),
                "plate_particles": a.get("n_particles"), "window_particles": b.get("n_particles"),
                "window_steady_state_time_s": b.get("steady_state_time_s")}
        report["reference"] = cmp_
        print(f"    whole plate: {cmp_['plate_particles']} particles, {cmp_['plate_wall_s']:.0f} s, bead "
              f"{cmp_['plate_width_mm']:.3g} x {cmp_['plate_height_mm']:.3g} mm")
        print(f"    window:      {cmp_['window_particles']} particles, {cmp_['window_wall_s']:.0f} s (steady at "
              f"{cmp_['window_steady_state_time_s']} s), bead {cmp_['window_width_mm']:.3g} x "
              f"{cmp_['window_height_mm']:.3g} mm")
        print(f"    difference: width {cmp_['width_difference']:+.1%}, height {cmp_['height_difference']:+.1%}; "
              f"wall-time ratio {cmp_['speedup']:.1f}")

    write_json(out / "bench.json", report)
    _chart(report, out / "speed_accuracy.png")
    print(f"written: {out / 'bench.json'}, {out / 'speed_accuracy.png'}")
    return report


def _chart(report: dict, path: Path) -> None:
    """Wall time against the error versus Table 1 (per mode) and versus the whole plate (reference)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from beadsim.io import save_figure

    fig, ax = plt.subplots(figsize=(6, 4))
    for mode, v in report.get("modes", {}).items():
        for key, marker in (("width_error", "o"), ("height_error", "s")):
            if v.get(key) is not None and math.isfinite(v[key]):
                ax.scatter(v["wall_s"] / 60, abs(v[key]) * 100, marker=marker, label=f"mode {mode} {key[:-6]} vs Table 1")
    ref = report.get("reference")
    if ref:
        for key, marker in (("width_difference", "^"), ("height_difference", "v")):
            if ref.get(key) is not None and math.isfinite(ref[key]):
                ax.scatter(ref["window_wall_s"] / 60, abs(ref[key]) * 100, marker=marker, color="k",
                           label=f"window vs whole plate ({key[:-11]}), dx {report['args']['ref_dx']}")
        ax.axvline(ref["plate_wall_s"] / 60, color="grey", ls=":",
                   label="whole plate, 2 s (reference dx)" + (" FAILED" if ref.get("status") else ""))
    if report.get("plate", {}).get("wall_2s_s"):
        ax.axvline(report["plate"]["wall_2s_s"] / 60, color="grey", ls="--",
                   label=f"whole plate, 2 s, dx {report['args']['dx']} ({'est.' if report['plate']['estimated'] else 'meas.'})")
    ax.axvline(10, color="red", lw=0.8, label="target 10 min")
    ax.set_xscale("log")
    ax.set_xlabel("wall time, min (2 cores)")
    ax.set_ylabel("|error|, %")
    ax.legend(fontsize=6)
    save_figure(fig, path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
