"""A backend written in Python: the solver of examples/plugin_gate_euler.c
(semi-implicit Euler, a damper implicit in the step's final velocity,
sequential impulses with restitution, the body moved out of penetration)
as a class, which beamsim's runner drives with the same scenes, random-force
schedules, outcomes, energy ledger and statistics as its own backends:

    PYTHONPATH=build/python python3 examples/python_backend.py configs/thesis/h1_symmetric.yaml 20

runs H1 on it beside the thesis backend (beamsim.compare) and prints the
comparison's headline. A backend in Python is a class with

    __init__(self, scene)          the world of a scene (a dict: body, beams,
                                   contact, dt; docs/bindings.md)
    advance(self, force, torque, h)   one step of h seconds under the force
                                   (F_x, F_y) on the body's centre
    state(self)                    a dict: x, v (2 numbers), theta, omega (one
                                   per beam), and optionally impulse (N s, what
                                   each beam exchanged with the body in the
                                   step), energy (the step's losses: damper,
                                   impact, contact, correction, J), heading,
                                   angular_velocity

and, optionally, a name (the class's name otherwise) and
set_state(self, state) (for the accuracy study's restarts)."""

import math
import sys


class GateEulerPy:
    """the gate_euler plug-in's solver in Python: semi-implicit Euler, impulses"""

    name = "gate_euler_py"

    def __init__(self, scene, iterations=10, slop=1e-4):
        body = scene["body"]
        if body["shape"] != "disk" or body["rotates"] or scene["contact"]["friction"] > 0:
            raise ValueError("gate_euler_py simulates a disk that does not turn, without "
                             "contact friction")
        self.m, self.r = body["mass"], body["radius"]
        self.x, self.v = list(body["start"]), list(body["velocity"])
        c = scene["contact"]
        self.e_tip, self.e_tan, self.rest = c["tip_restitution"], c["restitution"], \
            c["rest_threshold"]
        self.beams = [dict(b, theta=b["initial_theta"], omega=b["initial_omega"])
                      for b in scene["beams"]]
        self.iterations, self.slop = iterations, slop
        self.impulse = [0.0] * len(self.beams)
        self.energy = {"damper": 0.0, "impact": 0.0, "contact": 0.0, "correction": 0.0}

    def _direction(self, b):
        a = b["forward_sign"] * b["theta"]
        u0 = b["rest_direction"]
        return (math.cos(a) * u0[0] - math.sin(a) * u0[1],
                math.sin(a) * u0[0] + math.cos(a) * u0[1])

    def _offset(self, b):
        """C - Q, the nearest point's distance s along the beam, and whether
        Q is the tip."""
        u = self._direction(b)
        dx, dy = self.x[0] - b["pivot"][0], self.x[1] - b["pivot"][1]
        s = dx * u[0] + dy * u[1]
        tip = not 0.0 < s < b["length"]
        s = min(max(s, 0.0), b["length"])
        return (dx - s * u[0], dy - s * u[1]), s, u, tip

    def advance(self, force, torque, h):
        e = self.energy = {"damper": 0.0, "impact": 0.0, "contact": 0.0, "correction": 0.0}
        self.v[0] += h * force[0] / self.m
        self.v[1] += h * force[1] / self.m
        for b in self.beams:
            b["omega"] -= h * b["stiffness"] * b["theta"] / b["inertia"]
            b["damper"] = 0.0
        self.impulse = [0.0] * len(self.beams)
        contacts = []
        for i, b in enumerate(self.beams):
            d, s, u, tip = self._offset(b)
            dist = math.hypot(d[0], d[1])
            if not dist > 0.0:
                continue
            n = (d[0] / dist, d[1] / dist)
            lever = b["forward_sign"] * s * (-u[1] * n[0] + u[0] * n[1])
            inv = 1.0 / self.m + lever * lever / b["inertia"]
            gap = dist - self.r
            vn = n[0] * self.v[0] + n[1] * self.v[1] - b["omega"] * lever
            if gap + h * vn >= 0.0:
                continue
            impact = vn < -self.rest
            target = -(self.e_tip if tip else self.e_tan) * vn if impact else -max(gap, 0.0) / h
            contacts.append([i, n, lever, inv, target, impact, 0.0, 0.0])
        for _ in range(self.iterations if contacts else 1):
            for b in self.beams:  # the dampers, implicit in the final velocity
                if b["damping"] == 0.0:
                    continue
                hc = h * b["damping"]
                dmp = -hc * (b["omega"] - b["damper"] / b["inertia"]) / (1.0 + hc / b["inertia"])
                dd, w0 = dmp - b["damper"], b["omega"]
                b["damper"] = dmp
                b["omega"] += dd / b["inertia"]
                e["damper"] -= dd * 0.5 * (w0 + b["omega"])
            for c in contacts:
                i, n, lever, inv, target, impact, p_acc, work = c
                b = self.beams[i]
                vn = n[0] * self.v[0] + n[1] * self.v[1] - b["omega"] * lever
                p = max(p_acc + (target - vn) / inv, 0.0)
                dp = p - p_acc
                if dp == 0.0:
                    continue
                self.v[0] += dp * n[0] / self.m
                self.v[1] += dp * n[1] / self.m
                b["omega"] -= dp * lever / b["inertia"]
                vn1 = n[0] * self.v[0] + n[1] * self.v[1] - b["omega"] * lever
                c[6], c[7] = p, work + dp * 0.5 * (vn + vn1)
        for i, n, lever, inv, target, impact, p, work in contacts:
            self.impulse[i] = p
            e["impact" if impact else "contact"] -= work
        self.x[0] += h * self.v[0]
        self.x[1] += h * self.v[1]
        for b in self.beams:
            b["theta"] += h * b["omega"]
        for b in self.beams:  # out of any penetration deeper than slop
            d, s, u, tip = self._offset(b)
            dist = math.hypot(d[0], d[1])
            depth = self.r - dist
            if dist > 0.0 and depth > self.slop:
                move = (depth - self.slop) / dist
                self.x[0] += move * d[0]
                self.x[1] += move * d[1]
                e["correction"] += force[0] * move * d[0] + force[1] * move * d[1]

    def state(self):
        return {"x": self.x, "v": self.v, "theta": [b["theta"] for b in self.beams],
                "omega": [b["omega"] for b in self.beams], "impulse": self.impulse,
                "energy": self.energy}

    def set_state(self, s):
        self.x, self.v = list(s["x"]), list(s["v"])
        for b, theta, omega in zip(self.beams, s["theta"], s["omega"]):
            b["theta"], b["omega"] = theta, omega


if __name__ == "__main__":
    import beamsim

    experiment = sys.argv[1] if len(sys.argv) > 1 else "configs/thesis/h1_symmetric.yaml"
    trials = int(sys.argv[2]) if len(sys.argv) > 2 else 20
    r = beamsim.compare(experiment, backends=["thesis", GateEulerPy], trials=trials)
    print(f"thesis vs {GateEulerPy.name} on {experiment}, {trials} trials a group: "
          f"{r['n_disagree']} of {len(r['report']['groups'])} groups disagree")
