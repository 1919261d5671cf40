"""Runs a scene written by `nanofold export mujoco` in MuJoCo and reports its first contact.

MuJoCo integrates the model as written (RK4 at the file's time step, from the `start`
keyframe). Two things nanofold models that MJCF cannot say are added here:
- drag, F = -1/2 C_D rho A |v|^2 sgn(v.n) n at each plate's centre of mass (n the plate's
  body z), from the file's custom numerics, set as xfrc_applied by MuJoCo's passive-force
  callback, so every RK4 stage sees it;
- nanofold's contact events, measured on MuJoCo's state: a plate corner (a site) reaching the
  substrate's quarter-space {y <= edge, z <= 0} or the plane of a plate two or more links away
  while inside its outline, and a hinge folding flat (|angle| reaching pi). The time is
  interpolated linearly inside the step.
MuJoCo's own first contact between geoms (which have the plates' thickness) is reported beside.

Usage: python nanofold_mujoco.py MODEL.xml T_MAX_US   (prints one JSON object)
"""

import json
import math
import sys
import time

import mujoco
import numpy as np


def numeric(model, name):
    index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_NUMERIC, name)
    if index < 0:
        return None
    start = model.numeric_adr[index]
    return model.numeric_data[start : start + model.numeric_size[index]]


def install_drag(model):
    cd = numeric(model, "nanofold:drag_coefficient")
    rho = numeric(model, "nanofold:air_density")
    if cd is None or rho is None:
        mujoco.set_mjcb_passive(None)
        return 0
    cd, rho = float(cd[0]), float(rho[0])
    bodies, areas = [], []
    for body in range(model.nbody):
        area = numeric(model, "nanofold:drag_area:" + model.body(body).name)
        if area is not None:
            bodies.append(body)
            areas.append(float(area[0]))
    bodies = np.array(bodies, dtype=int)
    scale = -0.5 * cd * rho * np.array(areas)
    roots = model.body_rootid[bodies]

    # All plates at once. Each body's frame is its centre of mass, where the force acts; its
    # velocity there from MuJoCo's com-based velocity (about the subtree centre of its root,
    # computed before the passive forces). The force goes in as xfrc_applied, which the
    # same stage's accelerations include.
    def passive(m, d):
        cvel = d.cvel[bodies]
        v = cvel[:, 3:] + np.cross(cvel[:, :3], d.xipos[bodies] - d.subtree_com[roots])
        n = d.xmat[bodies][:, [2, 5, 8]]
        normal_speed = np.einsum("ij,ij->i", v, n)
        magnitude = scale * np.einsum("ij,ij->i", v, v) * np.sign(normal_speed)
        d.xfrc_applied[bodies, :3] = magnitude[:, None] * n
        d.xfrc_applied[bodies, 3:] = 0.0

    mujoco.set_mjcb_passive(passive)
    return len(areas)


def plate_index(name):
    # plate_i (strip) or sector_k (closed); None for other bodies.
    for prefix in ("plate_", "sector_"):
        if name.startswith(prefix) and name[len(prefix) :].isdigit():
            return int(name[len(prefix) :])
    return None


class Events:
    """nanofold's contact candidates as signed gaps on MuJoCo's state."""

    def __init__(self, model, data):
        self.model = model
        edge = numeric(model, "nanofold:substrate_edge_y")
        self.edge = None if edge is None else float(edge[0])
        self.strip = self.edge is not None
        self.corners = {}  # body -> [site ids]
        for site in range(model.nsite):
            body = int(model.site_bodyid[site])
            self.corners.setdefault(body, []).append(site)
        self.plates = [b for b in self.corners if plate_index(model.body(b).name) is not None]
        extent = max(np.linalg.norm(data.site_xpos[s]) for s in range(model.nsite))
        self.tolerance = 1e-9 * extent
        # Corners already on the substrate at the start (the anchoring hinge's line).
        self.substrate = []
        if self.strip:
            for body in self.plates:
                for site in self.corners[body]:
                    if abs(self.substrate_gap(data.site_xpos[site])) > 1e-6 * extent:
                        self.substrate.append((body, site))
        # Face candidates: strips, plates two or more links apart.
        self.faces = []
        if self.strip:
            for face in self.plates:
                for body in self.plates:
                    i, j = plate_index(model.body(face).name), plate_index(model.body(body).name)
                    if abs(i - j) >= 2:
                        self.faces += [(face, body, site) for site in self.corners[body]]
        # Folds: every hinge of a closed chain reaching +-pi.
        self.folds = []
        if not self.strip:
            for joint in range(model.njnt):
                if model.jnt_type[joint] == mujoco.mjtJoint.mjJNT_HINGE:
                    self.folds.append(joint)

    def substrate_gap(self, p):
        dy, dz = p[1] - self.edge, p[2]
        distance = math.hypot(dy, dz) if dy > 0 and dz > 0 else max(dy, dz)
        return distance - self.tolerance

    def inside(self, data, face, p):
        local = data.xmat[face].reshape(3, 3).T @ (p - data.xpos[face])
        outline = [self.model.site_pos[s] for s in self.corners[face]]
        for k in range(len(outline)):
            a, b = outline[k], outline[(k + 1) % len(outline)]
            edge = b - a
            if (edge[0] * (local[1] - a[1]) - edge[1] * (local[0] - a[0])) / math.hypot(edge[0], edge[1]) < -self.tolerance:
                return False
        return True

    def gaps(self, data):
        out = []
        for body, site in self.substrate:
            out.append((("substrate", self.model.body(body).name), self.substrate_gap(data.site_xpos[site]), None))
        for face, body, site in self.faces:
            p = data.site_xpos[site]
            n = data.xmat[face].reshape(3, 3)[:, 2]
            out.append(((self.model.body(face).name, self.model.body(body).name), float(n @ (p - data.xpos[face])), (face, p.copy())))
        for joint in self.folds:
            angle = data.qpos[self.model.jnt_qposadr[joint]]
            out.append(((self.model.joint(joint).name, "folded flat"), math.pi - abs(angle), None))
        return out


def main():
    path, t_max = sys.argv[1], float(sys.argv[2])
    model = mujoco.MjModel.from_xml_path(path)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    drag_bodies = install_drag(model)
    events = Events(model, data)
    dt = model.opt.timestep
    previous = events.gaps(data)
    first = None
    own_contact = None
    equality_violation = 0.0
    steps = 0
    clock = time.perf_counter()
    while data.time < t_max and first is None:
        t0 = data.time
        mujoco.mj_step(model, data)
        steps += 1
        if own_contact is None and data.ncon > 0:
            c = data.contact[0]
            own_contact = {"time_us": data.time, "geoms": [model.geom(c.geom1).name, model.geom(c.geom2).name]}
        rows = data.efc_type[: data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        if rows.any():
            equality_violation = max(equality_violation, float(np.abs(data.efc_pos[: data.nefc][rows]).max()))
        current = events.gaps(data)
        for (pair, before, _), (_, after, gate) in zip(previous, current):
            if before > 0.0 >= after:
                if gate is not None and not events.inside(data, gate[0], gate[1]):
                    continue
                t = t0 + dt * before / (before - after)
                if first is None or t < first["time_us"]:
                    first = {"time_us": t, "pair": list(pair)}
        previous = current
    print(
        json.dumps(
            {
                "mujoco_version": mujoco.__version__,
                "timestep_us": dt,
                "integrator": "RK4",
                "drag_bodies": drag_bodies,
                "steps": steps,
                "first_contact": first,
                "mujoco_geom_contact": own_contact,
                "max_equality_violation": equality_violation,
                "final_time_us": data.time,
                "final_qpos": [float(q) for q in data.qpos],
                "final_qvel": [float(v) for v in data.qvel],
                "joint_names": [model.joint(j).name for j in range(model.njnt)],
                "seconds": time.perf_counter() - clock,
            }
        )
    )


if __name__ == "__main__":
    main()
