#!/usr/bin/env python3
"""Independent Python/scipy peer of geartherm's FZG C scene (docs/numerics.md "Peer comparison").

Same physics as `geartherm run models/fzg_c.toml --cycle wltc`, written again from the equations
(each block cites the Rust file it mirrors), integrated with scipy.integrate.solve_ivp
(BDF, Radau, LSODA) and a Jacobian that is analytic for the network and a forward difference in
the oil temperature for everything that depends on the oil properties (losses, rotating-disc h).

Shared with geartherm (input data, not equations): the model file models/fzg_c.toml, the oil
catalogue models/oils.toml, the WLTC trace models/cycles/wltc_class3b.csv, and ONE compiled
number: the pocketing integral K of the FZG C mesh (see `PocketK` below), which is not
re-integrated here (the pocket-area geometry of src/physics/losses/pocketing/ is ~1500 lines).

Pure numpy + scipy, Python >= 3.11 (tomllib). Usage:

    python3 benches/peer/fzg_peer.py [--method BDF] [--rtol 1e-6] [--atol 1e-6] [--check]

from /work/main (or pass --root).
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import os
import subprocess
import tempfile
import sys
import time
import tomllib
from dataclasses import dataclass

import numpy as np
from scipy.integrate import quad, solve_ivp

KELVIN = 273.15
STEFAN_BOLTZMANN = 5.670374419e-8  # src/physics/thermal.rs (CODATA 2018)
G_STD = 9.80665                    # src/physics/losses/churning/mod.rs STANDARD_GRAVITY


# --------------------------------------------------------------------------------------------
# Oil: Walther / ASTM D341 and linear density (src/physics/oil.rs)
# --------------------------------------------------------------------------------------------
class Oil:
    def __init__(self, nu40_cst: float, nu100_cst: float, rho15: float, alpha_t: float):
        z = lambda nu: nu + 0.7 + (math.exp(-1.47 - 1.84 * nu - 0.51 * nu * nu) if nu < 2.0 else 0.0)
        y1, y2 = math.log10(math.log10(z(nu40_cst))), math.log10(math.log10(z(nu100_cst)))
        x1, x2 = math.log10(313.15), math.log10(373.15)
        self.b = -(y2 - y1) / (x2 - x1)
        self.a = y1 + self.b * x1
        self.rho15, self.alpha_t = rho15, alpha_t

    def nu(self, t_k: float) -> float:
        """Kinematic viscosity, m²/s: ν = 10^(10^(A − B log10 T)) − 0.7 (+ low-ν Newton)."""
        zz = 10.0 ** (10.0 ** (self.a - self.b * math.log10(t_k)))
        nu = zz - 0.7
        if nu < 2.0:  # ASTM D341 low-viscosity correction, inverted by Newton
            nu = max(nu, 0.0)
            for _ in range(50):
                e = math.exp(-1.47 - 1.84 * nu - 0.51 * nu * nu)
                step = (nu + 0.7 + e - zz) / (1.0 + e * (-1.84 - 1.02 * nu))
                nu -= step
                if abs(step) <= 1e-15 * (1 + abs(nu)):
                    break
        return nu * 1e-6

    def rho(self, t_k: float) -> float:
        return self.rho15 * (1.0 + self.alpha_t * (t_k - 288.15))

    def props(self, t_k: float):
        nu = self.nu(t_k)
        rho = self.rho(t_k)
        return nu, rho, nu * rho


# --------------------------------------------------------------------------------------------
# Gear geometry (spur, external, given tip diameters and centre distance): ISO 21771 as in
# src/physics/geometry/{gear,mesh}.rs; only what the losses need.
# --------------------------------------------------------------------------------------------
@dataclass
class GearGeo:
    name: str
    z: int
    m: float
    alpha: float
    x: float
    b: float
    ra: float
    rf: float
    r: float
    rb: float
    ra_um: float


def gear_geometry(g: dict) -> GearGeo:
    assert g.get("helix_angle_deg", 0.0) == 0.0, "peer supports spur gears only"
    m = g["module_mm"] * 1e-3
    al = math.radians(g["pressure_angle_deg"])
    z = g["teeth"]
    x = g["profile_shift"]
    r = 0.5 * m * z
    d_a = g["tip_diameter_mm"] * 1e-3 if "tip_diameter_mm" in g else 2 * r + 2 * m * (1 + x)
    d_f = 2 * r - 2 * m * (1.25 - x)  # h_fP* = 1.25
    return GearGeo(g["name"], z, m, al, x, g["face_width_mm"] * 1e-3, d_a / 2, d_f / 2, r,
                   r * math.cos(al), g.get("roughness_ra_um", 0.5) * 1e-6)


# --------------------------------------------------------------------------------------------
# Churning, Changenet & Velex (src/physics/losses/churning/changenet.rs, immersion.rs)
# --------------------------------------------------------------------------------------------
class Changenet:
    LOW = (1.366, 0.45, 0.1, -0.6, -0.21)
    HIGH = (3.644, 0.1, -0.35, -0.88, 0.85)
    RE_LO, RE_HI = 6000.0, 9000.0

    def __init__(self, g: GearGeo, depth: float, v0: float):
        rp, b, ra = g.r, g.b, g.ra
        h = min(max(depth, 0.0), 2 * ra)
        th = math.acos(1.0 - min(max(h / ra, 0.0), 2.0))
        ht = g.ra - g.rf
        sm = rp * rp * (2 * th - math.sin(2 * th)) + 2 * rp * b * th \
            + 2 * g.z * th * ht * b / (math.pi * math.cos(g.alpha))
        d = 2 * rp
        self.rp, self.b = rp, b
        self.k = 0.5 * sm * rp ** 3
        lo, hi = self.LOW, self.HIGH
        self.low_geo = lo[0] * (h / d) ** lo[1] * (v0 / d ** 3) ** lo[2]
        self.high_geo = hi[0] * (h / d) ** hi[1] * (v0 / d ** 3) ** hi[2] * (b / d) ** hi[4]
        self.immersed = depth > 0

    def _low(self, w, nu):
        fr = w * w * self.rp / G_STD
        re = w * self.rp * self.rp / nu
        return self.low_geo * fr ** self.LOW[3] * re ** self.LOW[4]

    def _high(self, w):
        fr = w * w * self.rp / G_STD
        return self.high_geo * fr ** self.HIGH[3]

    def power(self, w: float, nu: float, rho: float) -> float:
        w = abs(w)
        if not self.immersed or w == 0.0:
            return 0.0
        rec = w * self.rp * self.b / nu
        if rec <= self.RE_LO:
            cm = self._low(w, nu)
        elif rec >= self.RE_HI:
            cm = self._high(w)
        else:  # log-linear bridge between the two laws evaluated at their band edges
            wa = self.RE_LO * nu / (self.rp * self.b)
            wb = self.RE_HI * nu / (self.rp * self.b)
            ca, cb = self._low(wa, nu), self._high(wb)
            t = math.log(rec / self.RE_LO) / math.log(self.RE_HI / self.RE_LO)
            cm = ca * (cb / ca) ** t
        return self.k * rho * w ** 3 * cm


# --------------------------------------------------------------------------------------------
# Pocketing (src/physics/losses/pocketing/power.rs, src/scene/losses.rs):
#   P = z1 ρ ω1³ K/(4π) per family, K = Σ families; ρ = f ρ_oil + (1 − f) ρ_mix,
#   f = wet share of the band ±2.25 m_n around the pitch point.
# K itself is NOT recomputed here: it is geartherm's compiled number, recovered from one call of
# `geartherm losses` (the P ∝ ρ ω³ law and the density mix are then checked at other points).
# physics.md §3/6 lists K = 1.7398e-9 + 1.5726e-9 m⁵ for this mesh at C_d = 0.65 (fallback).
# --------------------------------------------------------------------------------------------
POCKET_K_DOC = 1.7398e-9 + 1.5726e-9


def peer_model(src: str, dst: str) -> str:
    """Copy a model file without its [[bearings]] and [[seals]] tables (the peer does not model
    them) and with the friction law the peer implements pinned in [losses] (geartherm's default
    is Schlenk); both tools then run the same network and
    the same equations from `dst`."""
    out, skip = [], False
    with open(src) as f:
        for line in f:
            if line.startswith("["):
                skip = line.strip() in ("[[bearings]]", "[[seals]]")
                assert line.strip() != "[losses]", "model has its own [losses]: edit peer_model"
            if not skip:
                out.append(line)
    out.append('\n[losses]\nfriction = "iso_tc60"\n')
    with open(dst, "w") as f:
        f.writelines(out)
    return dst


def pocket_k_from_geartherm(root: str, exe: str, model: str, z1: int, rho_p_of) -> float | None:
    try:
        out = subprocess.run([exe, "losses", model, "--gear", "1", "--speed-rpm", "3000",
                              "--torque-nm", "0", "--oil-temp-c", "60", "--json"],
                             cwd=root, capture_output=True, text=True, check=True).stdout
        js = json.loads(out)
    except Exception:
        return None
    p = sum(i["w"] for i in js["items"] if i["source"] == "pocketing")
    w1 = 3000 * math.pi / 30
    return p * 4 * math.pi / (z1 * rho_p_of(js["oil_density_kg_m3"]) * w1 ** 3)


# --------------------------------------------------------------------------------------------
# Sliding, detailed spur model, ISO TC60 local μ, uniform load sharing, first order
# (src/physics/losses/sliding/{contact,friction,mesh}.rs). Base-pitch average of Σ μ F v_g:
#   P = (ω1+ω2)/p_bt ∫_A^E μ(s) F(s) |s| ds,  F = T1/(r_b1 n(s)),  n = 2 on A..B and D..E, else 1,
#   μ = 0.12 (1e-3 · w Ra/(η R v_Σ))^0.25 (SI bracket), w = F/b, R = ρ1ρ2/(ρ1+ρ2),
#   v_Σ = ω1ρ1 + ω2ρ2 = ω1(ρ1 + ρ2 z1/z2).
# With the speed ratio fixed, μF|s| factorises: P = C · (ω1+ω2) T^1.25 (η ω1)^−0.25 G/(p_bt r_b1^1.25 b^.25), the
# geometric integral G = ∫ n^−1.25 |s| (R (ρ1 + ρ2 z1/z2))^−0.25 ds, done once by adaptive quad.
# --------------------------------------------------------------------------------------------
class Sliding:
    def __init__(self, g1: GearGeo, g2: GearGeo, a_w: float):
        a = g1.r + g2.r
        self.awt = math.acos(a * math.cos(g1.alpha) / a_w)
        t = math.tan(self.awt)
        self.t1c, self.t2c = g1.rb * t, g2.rb * t
        self.s_e = math.sqrt(g1.ra ** 2 - g1.rb ** 2) - self.t1c
        self.s_a = self.t2c - math.sqrt(g2.ra ** 2 - g2.rb ** 2)
        self.p_bt = math.pi * g1.m * math.cos(g1.alpha)
        self.eps_alpha = (self.s_e - self.s_a) / self.p_bt
        assert 1.0 <= self.eps_alpha < 2.0
        self.s_b = self.s_e - self.p_bt
        self.s_d = self.s_a + self.p_bt
        self.u = g1.z / g2.z
        self.rb1, self.b = g1.rb, min(g1.b, g2.b)
        self.ra = 0.5 * (g1.ra_um + g2.ra_um)

        def integrand(s):
            r1, r2 = self.t1c + s, self.t2c - s
            rr = r1 * r2 / (r1 + r2)
            n = 1.0 if self.s_b <= s <= self.s_d else 2.0
            return n ** -1.25 * abs(s) * (rr * (r1 + r2 * self.u)) ** -0.25

        pts = sorted([self.s_a, self.s_b, 0.0, self.s_d, self.s_e])
        self.G = sum(quad(integrand, lo, hi, epsabs=0, epsrel=1e-13, limit=200)[0]
                     for lo, hi in zip(pts[:-1], pts[1:]))

    def power(self, torque: float, w1: float, eta: float) -> float:
        t, w1 = abs(torque), abs(w1)
        if t == 0.0 or w1 == 0.0:
            return 0.0
        w2 = w1 * self.u
        c = 0.12 * (1e-3 * self.ra / (self.b * self.rb1 * eta * w1)) ** 0.25
        return (w1 + w2) / self.p_bt * c * t ** 1.25 / self.rb1 * self.G

    def power_quad(self, torque, w1, eta):
        """Same loss without the factorisation (per-point quad; used only as a self-check)."""
        t, w1 = abs(torque), abs(w1)
        w2 = w1 * self.u

        def f(s):
            r1, r2 = self.t1c + s, self.t2c - s
            rr = r1 * r2 / (r1 + r2)
            n = 1.0 if self.s_b <= s <= self.s_d else 2.0
            force = t / (self.rb1 * n)
            mu = 0.12 * (1e-3 * (force / self.b) * self.ra / (eta * rr * (w1 * r1 + w2 * r2))) ** 0.25
            return mu * force * abs(s) * (w1 + w2)

        pts = sorted([self.s_a, self.s_b, 0.0, self.s_d, self.s_e])
        return sum(quad(f, lo, hi, epsrel=1e-12)[0] for lo, hi in zip(pts[:-1], pts[1:])) / self.p_bt


# --------------------------------------------------------------------------------------------
# Rotating disc in oil (src/physics/thermal.rs rotating_disc_h; oil k 0.13, cp 2000 for Pr)
# --------------------------------------------------------------------------------------------
OIL_K, OIL_CP = 0.13, 2000.0


def rotating_disc_h(w: float, r: float, nu: float, pr: float, k: float) -> float:
    re = abs(w) * r * r / nu
    nl = 0.36 * math.sqrt(re)
    nt = 0.015 * re ** 0.8
    return (nl ** 4 + nt ** 4) ** 0.25 * pr ** (1.0 / 3.0) * k / r


# --------------------------------------------------------------------------------------------
# The scene: losses + network (src/scene/{losses,thermal,system}.rs)
# State y = [T_nodes (K) | E_items (J) | E_to_boundaries (J)]
# --------------------------------------------------------------------------------------------
class Scene:
    def __init__(self, root: str = ".", exe: str | None = None, pocket_k: float | None = None,
                 model: str | None = None):
        self.root = root
        model_path = os.path.abspath(model or os.path.join(root, "models", "fzg_c.toml"))
        self.model_path = model_path
        with open(model_path, "rb") as f:
            md = tomllib.load(f)
        # rolling bearings and seals are not modelled here: compare.py runs both tools
        # on a copy of models/fzg_c.toml without them (see peer_model)
        assert not md.get("bearings") and not md.get("seals"), \
            "peer models no bearings/seals: use peer_model(models/fzg_c.toml)"
        with open(os.path.join(root, "models", "oils.toml"), "rb") as f:
            oils = tomllib.load(f)
        self.md = md
        oc = next(o for o in oils["oil"] if o["key"] == md["oil"]["catalogue"])
        self.oil = Oil(oc["nu40_cst"], oc["nu100_cst"], oc["rho15_kg_m3"],
                       oc.get("thermal_expansion_per_k", -6.5e-4))
        gears = {g["name"]: gear_geometry(g) for g in md["gears"]}
        mesh = md["meshes"][0]
        g1, g2 = gears[mesh["gears"][0]], gears[mesh["gears"][1]]
        self.g1, self.g2 = g1, g2
        a_w = mesh["centre_distance_mm"] * 1e-3
        # kinematics of the single external stage: input = gear 1's shaft
        self.gear_speed = {g1.name: 1.0, g2.name: g1.z / g2.z}
        self.ratio = g2.z / g1.z
        lub = md["lubrication"]
        level = lub["oil_level_mm"] * 1e-3
        v0 = lub["sump_volume_l"] * 1e-3
        losses = md.get("losses", {})
        assert losses.get("churning", "changenet") == "changenet"
        assert losses.get("sliding", "detailed") == "detailed"
        assert losses.get("friction") == "iso_tc60"  # geartherm's default is schlenk
        assert losses.get("load_sharing", "uniform") == "uniform"
        # churning items (gears reaching the oil)
        self.churn = []
        for g in (g1, g2):
            depth = level - (lub["centre_height_mm"][g.name] * 1e-3 - g.ra)
            if depth > 0:
                self.churn.append((g.name, Changenet(g, depth, v0)))
        # pocketing density: wet share of the mesh band
        cd = losses.get("pocketing_discharge_coefficient", 0.65)
        assert cd == 0.65
        # unset: the share of the mesh zone above the oil pumps nothing (src/scene/losses.rs)
        rho_mix = losses.get("pocketing_mixture_density_kg_m3", 0.0)
        h1 = lub["centre_height_mm"][g1.name] * 1e-3
        h2 = lub["centre_height_mm"][g2.name] * 1e-3
        sl = Sliding(g1, g2, a_w)
        self.sliding = sl
        r_w1 = g1.rb / math.cos(sl.awt)
        y_pitch = h1 + (h2 - h1) * r_w1 / a_w
        band = 2.25 * g1.m
        self.wet = min(max((level - (y_pitch - band)) / (2 * band), 0.0), 1.0)
        self.rho_mix = rho_mix
        self.rho_pocket = lambda rho: self.wet * rho + (1 - self.wet) * rho_mix
        if pocket_k is None and exe is not None:
            pocket_k = pocket_k_from_geartherm(root, exe, model_path, g1.z, self.rho_pocket)
        self.pocket_k = pocket_k if pocket_k is not None else POCKET_K_DOC
        self.pocket_z1 = g1.z
        self.item_names = [f"churning:{n}" for n, _ in self.churn] + \
            [f"pocketing:{mesh['name']}", f"sliding:{mesh['name']}"]
        self.m_items = len(self.item_names)

        # thermal network
        th = md["thermal"]
        self.node_names = [n["name"] for n in th["nodes"]]
        self.n = len(self.node_names)
        self.cap = np.array([n.get("capacity_j_per_k", n.get("mass_kg", 0) * n.get("cp_j_per_kgk", 0))
                             for n in th["nodes"]], float)
        self.t0 = np.array([n.get("initial_temp_c", th.get("initial_temp_c", 23.0)) + KELVIN
                            for n in th["nodes"]])
        self.oil_i = self.node_names.index(th["oil_node"])
        bnames = [b["name"] for b in th.get("boundaries", [])]
        self.bt = [b["temp_c"] + KELVIN for b in th["boundaries"]]
        idx = lambda name: ("n", self.node_names.index(name)) if name in self.node_names \
            else ("b", bnames.index(name))
        self.fixed, self.rot, self.rad = [], [], []
        for l in th["links"]:
            a, b = idx(l["between"][0]), idx(l["between"][1])
            if "conductance_w_per_k" in l:
                self.fixed.append((a, b, l["conductance_w_per_k"]))
            elif "h_w_per_m2k" in l:
                self.fixed.append((a, b, l["h_w_per_m2k"] * l["area_m2"]))
            elif "rotating" in l:
                assert l["rotating"]["fluid"] == "oil"
                gn = l["rotating"]["gear"]
                self.rot.append((a, b, l["area_m2"], gears[gn].ra, self.gear_speed[gn]))
            elif "emissivity" in l:
                self.rad.append((a, b, STEFAN_BOLTZMANN * l["emissivity"] * l["area_m2"]))
            else:
                raise ValueError(f"unsupported link {l}")
        assert not th.get("heat")
        # coolers: q = eps*C * x(T_hot) * (T_hot - T_cold), x = smoothstep thermostat (thermal.rs)
        self.coolers = []
        for cl in th.get("coolers", []):
            ts = cl.get("thermostat")
            self.coolers.append((idx(cl["hot"]), idx(cl["cold"]),
                                 cl["effectiveness"] * cl["capacity_rate_w_per_k"],
                                 (ts["open_c"] + KELVIN, ts["full_c"] + KELVIN) if ts else None))
        # heat destinations: churning/pocketing → oil node; sliding → gear bodies 50/50
        body = {}
        for i, nd in enumerate(th["nodes"]):
            for gn in nd.get("gears", []):
                body[gn] = i
        self.heat_dest = [[(self.oil_i, 1.0)] for _ in self.churn] + [[(self.oil_i, 1.0)]] + \
            [[(body.get(g1.name, self.oil_i), 0.5), (body.get(g2.name, self.oil_i), 0.5)]]
        # constant part of the network as a matrix: heat_i = Σ_j A_ij T_j + c_i
        n = self.n
        self.A = np.zeros((n, n))
        self.c = np.zeros(n)
        self.Ab = np.zeros(n)    # heat to boundaries = Ab·T + cb
        self.cb = 0.0
        for (a, b, g) in self.fixed:
            self._add_lin(a, b, g)
        self.A_inv_cap = self.A / self.cap[:, None]

    def _add_lin(self, a, b, g, A=None, c=None):
        """Add q = g (T_a − T_b) from a to b to the linear arrays."""
        A = self.A if A is None else A
        for (end, sgn) in ((a, -1.0), (b, +1.0)):  # heat[end] += sgn*q
            kind, i = end
            if kind == "n":
                for (e2, s2) in ((a, 1.0), (b, -1.0)):
                    k2, j = e2
                    if k2 == "n":
                        A[i, j] += sgn * s2 * g
                    else:
                        self.c[i] += sgn * s2 * g * self.bt[j]
            else:  # heat into the boundary
                for (e2, s2) in ((a, 1.0), (b, -1.0)):
                    k2, j = e2
                    if k2 == "n":
                        self.Ab[j] += sgn * s2 * g
                    else:
                        self.cb += sgn * s2 * g * self.bt[j]

    # --- losses at an operating point (W per item) -------------------------------------------
    def losses(self, w_in: float, torque: float, t_oil: float):
        nu, rho, mu = self.oil.props(t_oil)
        q = [m.power(self.gear_speed[name] * w_in, nu, rho) for name, m in self.churn]
        q.append(self.pocket_z1 * self.rho_pocket(rho) * abs(w_in) ** 3 * self.pocket_k / (4 * math.pi))
        q.append(self.sliding.power(torque, w_in, mu))
        return q

    # --- RHS ---------------------------------------------------------------------------------
    def make_rhs(self, w_in: float, torque: float):
        n, m = self.n, self.m_items
        oil_i = self.oil_i
        A, c, cap, Ab, cb = self.A, self.c, self.cap, self.Ab, self.cb
        heat_dest, rot, rad, bt = self.heat_dest, self.rot, self.rad, self.bt
        oil = self.oil
        churn = self.churn
        gear_speed = self.gear_speed
        pocket_c = self.pocket_z1 * abs(w_in) ** 3 * self.pocket_k / (4 * math.pi)
        rho_pocket = self.rho_pocket
        sliding = self.sliding
        slide_on = torque != 0.0 and w_in != 0.0

        def oil_terms(temps, t_oil):
            """Heat per node (W) and into boundaries from the T_oil-dependent terms, plus q."""
            nu, rho, mu = oil.props(t_oil)
            q = [mm.power(gear_speed[name] * w_in, nu, rho) for name, mm in churn]
            q.append(pocket_c * rho_pocket(rho))
            q.append(sliding.power(torque, w_in, mu) if slide_on else 0.0)
            heat = np.zeros(n)
            for qk, dest in zip(q, heat_dest):
                for (node, f) in dest:
                    heat[node] += f * qk
            to_b = 0.0
            if w_in != 0.0:
                pr = mu * OIL_CP / OIL_K
                for (a, b, area, r, k) in rot:
                    g = area * rotating_disc_h(k * w_in, r, nu, pr, OIL_K)
                    qq = g * (temps[a[1]] - temps[b[1]])  # both ends are nodes in FZG
                    heat[a[1]] -= qq
                    heat[b[1]] += qq
            return heat, q, to_b

        def rad_terms(temps):
            heat = np.zeros(n)
            to_b = 0.0
            for (a, b, k) in rad:
                ta = temps[a[1]] if a[0] == "n" else bt[a[1]]
                tb = temps[b[1]] if b[0] == "n" else bt[b[1]]
                qq = k * (ta ** 4 - tb ** 4)
                if a[0] == "n":
                    heat[a[1]] -= qq
                else:
                    to_b -= qq
                if b[0] == "n":
                    heat[b[1]] += qq
                else:
                    to_b += qq
            return heat, to_b

        coolers = self.coolers

        def opening(th, ts):
            if ts is None:
                return 1.0, 0.0
            a, b = ts
            if th <= a:
                return 0.0, 0.0
            if th >= b:
                return 1.0, 0.0
            w = b - a
            x = (th - a) / w
            return x * x * (3 - 2 * x), 6 * x * (1 - x) / w

        def cooler_terms(temps):
            heat = np.zeros(n)
            to_b = 0.0
            for (hot, cold, g, ts) in coolers:
                th = temps[hot[1]]
                tc = temps[cold[1]] if cold[0] == "n" else bt[cold[1]]
                x, _ = opening(th, ts)
                qq = g * x * (th - tc)
                heat[hot[1]] -= qq
                if cold[0] == "n":
                    heat[cold[1]] += qq
                else:
                    to_b += qq
            return heat, to_b

        def rhs(t, y):
            temps = y[:n]
            h1, q, tb1 = oil_terms(temps, temps[oil_i])
            h2, tb2 = rad_terms(temps)
            h3, tb3 = cooler_terms(temps)
            tb2 += tb3
            heat = A @ temps + c + h1 + h2 + h3
            dy = np.empty(n + m + 1)
            dy[:n] = heat / cap
            dy[n:n + m] = q
            dy[n + m] = Ab @ temps + cb + tb1 + tb2
            return dy

        def jac(t, y):
            temps = y[:n]
            J = np.zeros((n + m + 1, n + m + 1))
            J[:n, :n] = A / cap[:, None]
            J[n + m, :n] = Ab
            # radiation (analytic)
            for (a, b, k) in rad:
                for (end, sgn) in ((a, 1.0), (b, -1.0)):
                    if end[0] != "n":
                        continue
                    j = end[1]
                    dq = sgn * 4 * k * temps[j] ** 3      # ∂q/∂T_j, q from a to b
                    for (e2, s2) in ((a, -1.0), (b, 1.0)):
                        if e2[0] == "n":
                            J[e2[1], j] += s2 * dq / cap[e2[1]]
                        else:
                            J[n + m, j] += s2 * dq
            # coolers (analytic)
            for (hot, cold, g, ts) in coolers:
                i = hot[1]
                th = temps[i]
                tc = temps[cold[1]] if cold[0] == "n" else bt[cold[1]]
                x, dx = opening(th, ts)
                dqh = g * (x + dx * (th - tc))
                J[i, i] -= dqh / cap[i]
                if cold[0] == "n":
                    j = cold[1]
                    J[j, i] += dqh / cap[j]
                    J[i, j] += g * x / cap[i]
                    J[j, j] -= g * x / cap[j]
                else:
                    J[n + m, i] += dqh
            # rotating links (analytic in the end temperatures, oil props held)
            t_oil = temps[oil_i]
            nu, rho, mu = oil.props(t_oil)
            if w_in != 0.0:
                pr = mu * OIL_CP / OIL_K
                for (a, b, area, r, k) in rot:
                    g = area * rotating_disc_h(k * w_in, r, nu, pr, OIL_K)
                    i, j = a[1], b[1]
                    J[i, i] -= g / cap[i]; J[i, j] += g / cap[i]
                    J[j, i] += g / cap[j]; J[j, j] -= g / cap[j]
            # oil-property dependence: forward difference in T_oil (temperatures held)
            hstep = 1e-4 * (1.0 + abs(t_oil) / 300.0)
            h0, q0, _ = oil_terms(temps, t_oil)
            h1, q1, _ = oil_terms(temps, t_oil + hstep)
            J[:n, oil_i] += (h1 - h0) / hstep / cap
            J[n:n + m, oil_i] += (np.array(q1) - np.array(q0)) / hstep
            return J

        return rhs, jac

    def y0(self):
        return np.concatenate([self.t0, np.zeros(self.m_items + 1)])


# --------------------------------------------------------------------------------------------
# Cycle → schedule (src/cycle/schedule.rs, src/cycle/vehicle.rs)
# --------------------------------------------------------------------------------------------
def schedule(scene: Scene, cycle_csv: str):
    veh = scene.md["vehicle"]
    rl = veh["road_load"]
    f0, f1, f2 = rl["f0_n"], rl["f1_n_per_mps"], rl["f2_n_per_mps2"]
    f0 += veh["mass_kg"] * G_STD * math.sin(math.atan(veh.get("grade_percent", 0.0) / 100))
    me = veh["mass_kg"] * (1 + veh.get("rotating_mass_factor", 0.04))
    rw, fd = veh["wheel_radius_m"], veh["final_drive_ratio"]
    vstand = veh.get("standstill_below_kmh", 0.1) / 3.6
    assert veh.get("overrun", "zero") == "zero"
    with open(cycle_csv) as f:
        rows = [(float(r["time_s"]), float(r["speed_kmh"]) / 3.6) for r in csv.DictReader(f)]
    out = []
    for (ta, va), (tb, vb) in zip(rows[:-1], rows[1:]):
        dt = tb - ta
        a = (vb - va) / dt
        m1 = 0.5 * (va + vb)
        m2 = (va * va + va * vb + vb * vb) / 3
        m3 = 0.25 * (va + vb) * (va * va + vb * vb)
        p = me * a * m1 + f0 * m1 + f1 * m2 + f2 * m3
        if va <= vstand and vb <= vstand:
            w_in, tq, pw = 0.0, 0.0, 0.0
        else:
            pw = max(p, 0.0)
            w_in = m1 * fd / rw * scene.ratio
            tq = pw / w_in
        out.append((ta, tb, w_in, tq, pw, m1))
    return out


# --------------------------------------------------------------------------------------------
# Drive: restart solve_ivp where the inputs jump, output at every interval end
# --------------------------------------------------------------------------------------------
def run(scene: Scene, sched, method="BDF", rtol=1e-6, atol=1e-6, use_jac=True):
    n, m = scene.n, scene.m_items
    atol_v = np.concatenate([np.full(n, atol), np.full(m + 1, atol * scene.cap.mean())])
    y = scene.y0()
    times = [sched[0][0]]
    states = [y.copy()]
    nfev = njev = nlu = 0
    k = 0
    t_start = time.perf_counter()
    while k < len(sched):
        # group the following intervals with identical inputs (geartherm restarts only at jumps)
        j = k
        while j + 1 < len(sched) and sched[j + 1][2] == sched[k][2] and sched[j + 1][3] == sched[k][3]:
            j += 1
        t0, t1 = sched[k][0], sched[j][1]
        teval = [s[1] for s in sched[k:j + 1]]
        rhs, jac = scene.make_rhs(sched[k][2], sched[k][3])
        kw = dict(method=method, rtol=rtol, atol=atol_v, t_eval=teval)
        if use_jac and method in ("BDF", "Radau", "LSODA"):
            kw["jac"] = jac
        sol = solve_ivp(rhs, (t0, t1), y, **kw)
        if not sol.success:
            raise RuntimeError(f"solve_ivp failed at t={t0}: {sol.message}")
        nfev += sol.nfev; njev += sol.njev; nlu += sol.nlu
        for col in range(sol.y.shape[1]):
            states.append(sol.y[:, col].copy())
        times.extend(sol.t.tolist())
        y = sol.y[:, -1].copy()
        y[-(m + 1):] = y[-(m + 1):]  # energies carried on
        k = j + 1
    wall = time.perf_counter() - t_start
    return dict(times=np.array(times), states=np.array(states), wall=wall,
                nfev=nfev, njev=njev, nlu=nlu)


def check_losses(scene: Scene, exe: str, points=None, verbose=True):
    """Compare every loss item with `geartherm losses` (the Python values are computed here)."""
    points = points or [(500, 20, 30), (1450, 135, 80), (3000, 60, 50), (800, 5, 23),
                        (2000, 100, 40), (4500, 150, 110), (1200, 40, 60)]
    rows = []
    for rpm, tq, tc in points:
        js = json.loads(subprocess.run(
            [exe, "losses", scene.model_path, "--gear", "1", "--speed-rpm", str(rpm),
             "--torque-nm", str(tq), "--oil-temp-c", str(tc), "--json"],
            cwd=scene.root, capture_output=True, text=True, check=True).stdout)
        q = scene.losses(rpm * math.pi / 30, tq, tc + KELVIN)
        gt = [i["w"] for i in js["items"]]
        nu_g = js["oil_viscosity_cst"]
        nu_p = scene.oil.nu(tc + KELVIN) * 1e6
        for name, a, b in zip(scene.item_names, q, gt):
            rows.append((rpm, tq, tc, name, a, b, (a - b) / b if b else 0.0))
        rows.append((rpm, tq, tc, "oil_nu_cst", nu_p, nu_g, (nu_p - nu_g) / nu_g))
        rows.append((rpm, tq, tc, "oil_rho", scene.oil.rho(tc + KELVIN), js["oil_density_kg_m3"],
                     scene.oil.rho(tc + KELVIN) / js["oil_density_kg_m3"] - 1))
    if verbose:
        for r in rows:
            print(f"{r[0]:6} rpm {r[1]:5} Nm {r[2]:5} C {r[3]:24} peer {r[4]:14.8g}  geartherm "
                  f"{r[5]:14.8g}  rel {r[6]:+.2e}")
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", default=".")
    ap.add_argument("--exe", default="target/release/geartherm")
    ap.add_argument("--method", default="BDF", choices=["BDF", "Radau", "LSODA"])
    ap.add_argument("--rtol", type=float, default=1e-6)
    ap.add_argument("--atol", type=float, default=1e-6)
    ap.add_argument("--check", action="store_true", help="compare losses with `geartherm losses`")
    args = ap.parse_args()
    exe = os.path.join(args.root, args.exe) if not os.path.isabs(args.exe) else args.exe
    model = peer_model(os.path.join(args.root, "models", "fzg_c.toml"),
                             os.path.join(tempfile.mkdtemp(prefix="fzg_peer_"), "fzg_c.toml"))
    scene = Scene(args.root, exe if os.path.exists(exe) else None, model=model)
    print(f"pocketing K = {scene.pocket_k:.10e} m^5 (doc {POCKET_K_DOC:.5e}); sliding G = "
          f"{scene.sliding.G:.10e}; eps_alpha = {scene.sliding.eps_alpha:.6f}")
    if args.check:
        check_losses(scene, exe)
    sched = schedule(scene, os.path.join(args.root, "models", "cycles", "wltc_class3b.csv"))
    r = run(scene, sched, args.method, args.rtol, args.atol)
    T = r["states"][-1, :scene.n] - KELVIN
    e = r["states"][-1, scene.n:scene.n + scene.m_items]
    print(f"{args.method} rtol {args.rtol:g}: wall {r['wall']:.3f} s, nfev {r['nfev']}, njev {r['njev']}, "
          f"nlu {r['nlu']}")
    print("final T (C):", dict(zip(scene.node_names, np.round(T, 6))))
    print("energy lost (J):", dict(zip(scene.item_names, np.round(e, 3))), "total", round(e.sum(), 3))


if __name__ == "__main__":
    main()
