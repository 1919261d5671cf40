"""A Miura-ori design sweep: panel angle × rows × cols → verdict, degrees of freedom (flat
and half folded) and the time to fold, on a Dask cluster; a figure of folding time against
panel count.

    python python/examples/miura_sweep.py                      # the full grid, a local cluster
    python python/examples/miura_sweep.py --small --out DIR    # the grid CI runs
    python python/examples/miura_sweep.py --scheduler tcp://host:8786
"""

import argparse
from pathlib import Path

import nanofold


def miura_design(angle_deg: float, rows: int, cols: int) -> dict:
    """One design: its verdict, DOF at flat (first order) and half folded, time to fold."""
    sheet = nanofold.generate.miura(rows, cols, angle_deg=angle_deg)
    verdict = nanofold.check(sheet)
    half = nanofold.fold(sheet, to=50)
    full = nanofold.fold(sheet, to=95)
    return {
        "verdict": verdict.verdict,
        "panels": rows * cols,
        "dof_flat": verdict.dof,
        "dof_half_folded": half.dof,
        "fold_stop": full.verdict,
        "fold_seconds": full.seconds,
        "fold_steps": full.steps,
        "closure_residual_rad": full.max_closure_residual_rad,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--small", action="store_true", help="a 2 × 2 × 2 grid (CI)")
    parser.add_argument("--out", default="output/miura_sweep", help="output folder (resumable)")
    parser.add_argument("--scheduler", help="a Dask scheduler address (default: a local cluster)")
    args = parser.parse_args()
    if args.small:
        grid = {"angle_deg": [45.0, 70.0], "rows": [3, 6], "cols": [3, 6]}
    else:
        grid = {"angle_deg": [30.0, 45.0, 60.0, 75.0], "rows": [4, 8, 16, 24], "cols": [4, 8, 16, 24]}
    table = nanofold.sweep(miura_design, grid, client=args.scheduler, out=args.out)
    print(table[["angle_deg", "rows", "cols", "verdict", "dof_flat", "dof_half_folded", "fold_stop", "fold_seconds"]]
          .to_string(index=False))
    figure(table, Path(args.out) / "miura_sweep.svg")


def figure(table, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter, ScalarFormatter

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    for k, (angle, runs) in enumerate(table.groupby("angle_deg")):
        left.scatter(runs["panels"], runs["fold_seconds"], s=22, color=f"C{k}", label=f"{angle:g}°")
        runs = runs.sort_values("panels")
        right.plot(runs["rows"] + runs["cols"], runs["dof_flat"], "o", color=f"C{k}", ms=5, label=f"{angle:g}°, flat")
    right.plot(table["rows"] + table["cols"], table["dof_half_folded"], "k_", ms=12, mew=2, label="half folded (all)")
    left.set_xscale("log")
    left.set_yscale("log")
    left.set_xticks([10, 20, 50, 100, 200, 500])
    for axis in (left.xaxis, left.yaxis):
        axis.set_major_formatter(ScalarFormatter())
        axis.set_minor_formatter(NullFormatter())
    left.set_xlabel("panels (rows × cols)")
    left.set_ylabel("time to fold to 95% (s)")
    left.set_title("time to fold, by panel angle")
    left.legend(title="panel angle")
    right.set_xlabel("rows + cols")
    right.set_ylabel("degrees of freedom")
    right.set_title("first-order DOF at flat, and half folded")
    right.legend(fontsize=8)
    for ax in (left, right):
        ax.grid(True, which="major", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
