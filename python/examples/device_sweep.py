"""A device sweep: the accordion bridge's hinge metal thickness × etch rate → its first
contact time and its frequency at the folded equilibrium, on a Dask cluster; a figure of
both against the two parameters.

    python python/examples/device_sweep.py                      # the full grid, a local cluster
    python python/examples/device_sweep.py --small --out DIR    # the grid CI runs
"""

import argparse
import math
from pathlib import Path

import nanofold

SCENE = Path(__file__).resolve().parents[2] / "patterns" / "bridge_ramp.scene.json"


def bridge(cr_thickness_um: float, etch_rate_um_per_min: float) -> dict:
    """One device: every hinge's Cr layer at this thickness, released at this etch rate."""
    scene = nanofold.Scene.open(SCENE)
    hinges = len(scene.to_dict()["hinges"])
    changes = {f"hinges.{i}.layers.1.thickness_um": cr_thickness_um for i in range(hinges)}
    changes["actuation.etch_rate_um_per_min"] = etch_rate_um_per_min
    # Long enough for the slowest front to reach the last hinge (the scene's own is 30 min).
    changes["time.t_end_s"] = 4 * 3600.0
    device = scene.replace(changes)
    response = nanofold.simulate(device)
    modes = nanofold.modes(device)
    contact = response.collision
    return {
        "model": response.model,
        "first_contact_s": contact["time_s"] if contact else math.nan,
        "contact_pair": " | ".join(contact["pair"]) if contact else None,
        "lowest_frequency_hz": float(min(modes.frequencies_hz)),
        "stable": modes.stable,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--small", action="store_true", help="a 3 × 2 grid (CI)")
    parser.add_argument("--out", default="output/device_sweep", help="output folder (resumable)")
    parser.add_argument("--scheduler", help="a Dask scheduler address (default: a local cluster)")
    args = parser.parse_args()
    if args.small:
        grid = {"cr_thickness_um": [0.05, 0.1, 0.2], "etch_rate_um_per_min": [1.5, 3.0]}
    else:
        grid = {
            "cr_thickness_um": [0.02, 0.05, 0.1, 0.15, 0.2, 0.3],
            "etch_rate_um_per_min": [0.5, 1.0, 1.5, 3.0, 6.0],
        }
    table = nanofold.sweep(bridge, grid, client=args.scheduler, out=args.out)
    print(table[["cr_thickness_um", "etch_rate_um_per_min", "model", "first_contact_s", "contact_pair",
                 "lowest_frequency_hz"]].to_string(index=False))
    figure(table, Path(args.out) / "device_sweep.svg")


def figure(table, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(9, 3.6))
    for rate, runs in table.groupby("etch_rate_um_per_min"):
        runs = runs.sort_values("cr_thickness_um")
        left.plot(runs["cr_thickness_um"], runs["first_contact_s"] / 60, "o-", label=f"{rate:g} µm/min")
    left.set_xlabel("Cr thickness of every hinge (µm)")
    left.set_ylabel("first contact (min)")
    left.set_title("release: first contact")
    left.set_ylim(0, 1.45 * (table["first_contact_s"].max() / 60))
    left.legend(title="etch rate", loc="upper center", ncol=3, fontsize=8)
    one_rate = table[table["etch_rate_um_per_min"] == table["etch_rate_um_per_min"].min()].sort_values("cr_thickness_um")
    right.plot(one_rate["cr_thickness_um"], one_rate["lowest_frequency_hz"] / 1e3, "s-", color="C3")
    right.set_xlabel("Cr thickness of every hinge (µm)")
    right.set_ylabel("lowest mode at the folded state (kHz)")
    right.set_title("folded: lowest natural frequency")
    for ax in (left, right):
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
