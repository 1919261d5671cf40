"""Task functions the sweep tests send to workers (a module, so workers import it)."""

import time

import nanofold


def miura_design(angle_deg, rows, cols):
    sheet = nanofold.generate.miura(rows, cols, angle_deg=angle_deg)
    folded = nanofold.fold(sheet, to=50)
    return {"verdict": nanofold.check(sheet).verdict, "dof": folded.dof, "steps": folded.steps}


def slow_square(x, delay=0.05):
    time.sleep(delay)
    if x == 13:
        raise ValueError("thirteen is refused")
    return {"square": x * x}
