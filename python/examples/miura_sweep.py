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
    half = nanofold.fold(sheet, to=0.5)
    full = nanofold.fold(sheet, to=0.95)
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

    fig, ax = plt.subplots(figsize=(6, 4))
    for angle, runs in table.groupby("angle_deg"):
        runs = runs.sort_values("panels")
        ax.loglog(runs["panels"], runs["fold_seconds"], "o-", label=f"{angle:g}°")
    ax.set_xlabel("panels (rows × cols)")
    ax.set_ylabel("time to fold to 95% (s)")
    ax.set_title("Miura-ori: rigid folding time by panel angle")
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(title="panel angle")
    fig.tight_layout()
    fig.savefig(path)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
