#!/usr/bin/env python3
"""Seed 001's target filter (peopletrack `track::pdaf`) against Stone Soup, step by step.

Reads the JSON files `examples/pdaf_agreement.rs` writes (our filter's every step on the
measurement sequences of a real and a synthetic laser log) and, from each step's prior (our
previous posterior), runs Stone Soup on the same measurements:

- CV: `KalmanPredictor` with `ConstantVelocity(q)` on x and y, and ω held at 0 (a 1x1
  `LinearGaussianTimeInvariantTransitionModel` with F = 0, Q = 0), in Stone Soup's state order
  (x, vx, y, vy, ω) — ours is (x, y, vx, vy, ω);
- CT: `ExtendedKalmanPredictor` with `ConstantTurn([q, q], q_ω)`; Stone Soup's EKF
  differentiates the transition numerically (`compute_jac`), ours analytically, so the model
  here adds the analytic Jacobian of the same transition (written out below from the closed
  form) — otherwise the two differ by the finite-difference error (~1e-8), not by a bug;
- association: `PDAHypothesiser` (P_D, clutter density λ as `clutter_spatial_density`, and
  `prob_gate` = P_G = 1 - exp(-g/2), whose chi2.ppf(P_G, 2) is our gate g) and `PDAUpdater`.
  Our likelihood ratios lr_j (seed 001's colour term) multiply the detection hypotheses'
  weights before normalising (the hypothesiser runs with `normalise=False`); our maneuver gate
  (a person's reach v_max dt + a_max dt^2/2 + 3 sigma_r from the last position that used a
  measurement) has no Stone Soup counterpart and is applied here as a pre-filter of the
  detections;
- IMM: Stone Soup 1.9 has no IMM (its 2019 IMM branch was never released), so the IMM
  recursion is written here from Stone Soup's pieces: Markov mixing with our per-second
  switching probability turned into a step's matrix (1 - (1 - s)^dt), mixed estimates and the
  combined estimate by `gm_reduce_single`, per-mode prediction by the predictors above,
  gating on the combined prediction, per-mode PDA hypotheses (`include_all=True` on the gated
  set) and `PDAUpdater`, mode probabilities from the hypotheses' unnormalised weights
  (Lambda_i = sum of the mode's missed and detection weights, the same up to 1/lambda for
  every mode).

Times: Stone Soup's timestamps are datetimes (microseconds); the example stamps scans to whole
microseconds, so both sides use the same dt.

Every compared number (prediction, gated set, beta, beta0, posterior state and covariance,
modes and their probabilities, the maneuver anchor) must agree to TOL; exits 1 otherwise.

Usage: stonesoup_pdaf_agreement.py DIR [--tol 1e-9]
"""

import argparse
import datetime
import glob
import json
import math
import os
import sys

import numpy as np
import stonesoup
from stonesoup.functions import gm_reduce_single
from stonesoup.hypothesiser.probability import PDAHypothesiser
from stonesoup.measures import SquaredMahalanobis
from stonesoup.models.measurement.linear import LinearGaussian
from stonesoup.models.transition.linear import (
    CombinedLinearGaussianTransitionModel,
    ConstantVelocity,
    LinearGaussianTimeInvariantTransitionModel,
)
from stonesoup.models.transition.nonlinear import ConstantTurn
from stonesoup.predictor.kalman import ExtendedKalmanPredictor, KalmanPredictor
from stonesoup.types.array import StateVectors
from stonesoup.types.detection import Detection
from stonesoup.types.multihypothesis import MultipleHypothesis
from stonesoup.types.numeric import Probability
from stonesoup.types.state import GaussianState
from stonesoup.types.track import Track
from stonesoup.updater.kalman import ExtendedKalmanUpdater
from stonesoup.updater.probability import PDAUpdater

# ours (x, y, vx, vy, w) -> Stone Soup (x, vx, y, vy, w)
PERM = [0, 2, 1, 3, 4]
BASE = datetime.datetime(2000, 1, 1)


def stamp(t):
    return BASE + datetime.timedelta(microseconds=round(t * 1e6))


def to_ss(x, p):
    x = np.asarray(x, float)[PERM]
    p = np.asarray(p, float)[np.ix_(PERM, PERM)]
    return x, p


def from_ss(x, p):
    inv = np.argsort(PERM)
    x = np.asarray(x, float).ravel()[inv]
    p = np.asarray(p, float)[np.ix_(inv, inv)]
    return x, p


class ConstantTurnAnalytic(ConstantTurn):
    """Stone Soup's coordinated turn with the analytic Jacobian of its transition."""

    def jacobian(self, state, **kwargs):
        dt = kwargs["time_interval"].total_seconds()
        x = np.asarray(state.state_vector, float).ravel()
        vx, vy, w = x[1], x[3], x[4]
        th = w * dt
        if abs(th) < 1e-4:
            # series of sin(th)/w, (1-cos th)/w and their w-derivatives
            s = dt * (1 - th**2 / 6 + th**4 / 120)
            c = dt * (th / 2 - th**3 / 24 + th**5 / 720)
            ds = dt * dt * (-th / 3 + th**3 / 30)
            dc = dt * dt * (0.5 - th**2 / 8 + th**4 / 144)
        else:
            s = math.sin(th) / w
            c = (1 - math.cos(th)) / w
            ds = (th * math.cos(th) - math.sin(th)) / (w * w)
            dc = (th * math.sin(th) - (1 - math.cos(th))) / (w * w)
        sn, cs = math.sin(th), math.cos(th)
        f = np.eye(5)
        # rows/cols in Stone Soup order (x, vx, y, vy, w)
        f[0, 1], f[0, 3], f[0, 4] = s, -c, ds * vx - dc * vy
        f[1, 1], f[1, 3], f[1, 4] = cs, -sn, -dt * (sn * vx + cs * vy)
        f[2, 1], f[2, 3], f[2, 4] = c, s, dc * vx + ds * vy
        f[3, 1], f[3, 3], f[3, 4] = sn, cs, dt * (cs * vx - sn * vy)
        return f


def models(params):
    q, qw = params["accel_noise"], params["turn_noise"]
    hold = LinearGaussianTimeInvariantTransitionModel(
        transition_matrix=np.zeros((1, 1)), covariance_matrix=np.zeros((1, 1))
    )
    cv = CombinedLinearGaussianTransitionModel(
        [ConstantVelocity(q), ConstantVelocity(q), hold]
    )
    ct = ConstantTurnAnalytic(linear_noise_coeffs=np.array([q, q]), turn_noise_coeff=qw)
    return {"cv": KalmanPredictor(cv), "ct": ExtendedKalmanPredictor(ct)}


class Checker:
    def __init__(self, params, tol):
        self.p = params
        self.tol = tol
        sr = params["sigma_r"]
        self.mm = LinearGaussian(ndim_state=5, mapping=(0, 2), noise_covar=np.eye(2) * sr * sr)
        self.updater = PDAUpdater(self.mm)
        self.ekf = ExtendedKalmanUpdater(self.mm)
        self.predictors = models(params)
        g = params["gate"]
        self.p_gate = 1.0 if g is None else 1.0 - math.exp(-0.5 * g)
        self.worst = 0.0
        self.where = ""
        self.gate_mismatch = 0

    def close(self, name, ours, theirs, step):
        d = float(np.max(np.abs(np.asarray(ours, float) - np.asarray(theirs, float)))) if np.size(ours) else 0.0
        if not np.isfinite(d):
            d = math.inf
        if d > self.worst:
            self.worst, self.where = d, f"step {step}: {name}"

    def hypothesiser(self, predictor, include_all):
        return PDAHypothesiser(
            predictor=predictor,
            updater=self.ekf,
            clutter_spatial_density=self.p["clutter_density"],
            prob_detect=self.p["p_d"],
            prob_gate=self.p_gate,
            include_all=include_all,
            normalise=False,
        )

    def maneuver(self, z, anchor, anchor_t, t):
        v_max, a_max, sr = self.p["v_max"], self.p["a_max"], self.p["sigma_r"]
        if v_max is None or a_max is None:
            return [True] * len(z)
        dt = t - anchor_t
        reach = v_max * dt + 0.5 * a_max * dt * dt if dt > 0 else 0.0
        r = reach + 3.0 * sr
        return [math.hypot(q[0] - anchor[0], q[1] - anchor[1]) <= r for q in z]

    def detections(self, z, idx, t):
        return [
            Detection(np.array([[z[j][0]], [z[j][1]]]), timestamp=stamp(t),
                      measurement_model=self.mm, metadata={"j": j})
            for j in idx
        ]

    def pda(self, predictor, prior, dets, lr, t, include_all):
        """Stone Soup's PDA on one mode: normalised hypotheses, their unnormalised sum, the
        update."""
        hyps = self.hypothesiser(predictor, include_all).hypothesise(Track([prior]), dets, stamp(t))
        for h in hyps:
            if h:
                h.probability = h.probability * Probability(lr[h.measurement.metadata["j"]])
        total = Probability.sum(h.probability for h in hyps)
        normed = MultipleHypothesis(list(hyps), normalise=True)
        return normed, float(total), self.updater.update(normed)

    def betas(self, normed, n):
        beta = [0.0] * n
        beta0 = 1.0
        for h in normed:
            if h:
                beta[h.measurement.metadata["j"]] = float(h.probability)
            else:
                beta0 = float(h.probability)
        return beta, beta0

    def single(self, model, step):
        k = step["scan"]
        prior = step["prior"]
        t0, t = prior["t"], step["t"]
        x0, p0 = to_ss(prior["modes"][0]["x"], prior["modes"][0]["P"])
        state = GaussianState(x0.reshape(5, 1), p0, timestamp=stamp(t0))
        pred = self.predictors[model].predict(state, timestamp=stamp(t))
        self.close("prediction x", step["pred"]["x"], from_ss(pred.state_vector, pred.covar)[0], k)
        self.close("prediction P", step["pred"]["P"], from_ss(pred.state_vector, pred.covar)[1], k)
        z, lr = step["z"], step["lr"]
        ok = self.maneuver(z, prior["anchor"], prior["anchor_t"], t)
        dets = self.detections(z, [j for j in range(len(z)) if ok[j]], t)
        normed, _, post = self.pda(self.predictors[model], state, dets, lr, t, False)
        gated = sorted(h.measurement.metadata["j"] for h in normed if h)
        if gated != step["gated"]:
            self.gate_mismatch += 1
            self.where = self.where or f"step {k}: gated {gated} vs ours {step['gated']}"
            return
        beta, beta0 = self.betas(normed, len(z))
        self.close("beta", step["beta"], beta, k)
        self.close("beta0", [step["beta0"]], [beta0], k)
        x, p = from_ss(post.state_vector, post.covar)
        self.close("posterior x", step["post"]["x"], x, k)
        self.close("posterior P", step["post"]["P"], p, k)
        self.anchor(step, x, beta, t, k)

    def anchor(self, step, x, beta, t, k):
        prior = step["prior"]
        a, at = (prior["anchor"], prior["anchor_t"])
        if any(b > 0 for b in beta):
            a, at = [x[0], x[1]], t
        self.close("maneuver anchor", step["post"]["anchor"] + [step["post"]["anchor_t"]], list(a) + [at], k)

    def imm(self, step):
        k = step["scan"]
        prior = step["prior"]
        t0, t = prior["t"], step["t"]
        dt = t - t0
        mu = np.asarray(prior["mu"], float)
        leave = 1.0 - (1.0 - self.p["imm_switch"]) ** dt
        pi = np.array([[1 - leave, leave], [leave, 1 - leave]])
        c = pi.T @ mu
        modes = [to_ss(m["x"], m["P"]) for m in prior["modes"]]
        means = StateVectors(np.hstack([m[0].reshape(5, 1) for m in modes]))
        covs = np.stack([m[1] for m in modes], axis=2)
        preds = []
        for j, name in enumerate(["cv", "ct"]):
            w = pi[:, j] * mu / c[j]
            xm, pm = gm_reduce_single(means, covs, w)
            mixed = GaussianState(np.asarray(xm).reshape(5, 1), np.asarray(pm), timestamp=stamp(t0))
            preds.append((name, mixed, self.predictors[name].predict(mixed, timestamp=stamp(t))))
        pm_means = StateVectors(np.hstack([np.asarray(pr[2].state_vector, float) for pr in preds]))
        pm_covs = np.stack([pr[2].covar for pr in preds], axis=2)
        xc, pc = gm_reduce_single(pm_means, pm_covs, c)
        comb = GaussianState(np.asarray(xc).reshape(5, 1), np.asarray(pc), timestamp=stamp(t))
        x, p = from_ss(comb.state_vector, comb.covar)
        self.close("IMM prediction x", step["pred"]["x"], x, k)
        self.close("IMM prediction P", step["pred"]["P"], p, k)
        z, lr = step["z"], step["lr"]
        ok = self.maneuver(z, prior["anchor"], prior["anchor_t"], t)
        meas = self.ekf.predict_measurement(comb, measurement_model=self.mm)
        g = self.p["gate"]
        idx = []
        for j, det in enumerate(self.detections(z, range(len(z)), t)):
            d2 = SquaredMahalanobis(state_covar_inv_cache_size=None)(meas, det)
            if ok[j] and (g is None or d2 <= g):
                idx.append(j)
        if idx != step["gated"]:
            self.gate_mismatch += 1
            self.where = self.where or f"step {k}: gated {idx} vs ours {step['gated']}"
            return
        dets = self.detections(z, idx, t)
        lam, posts, normeds = [], [], []
        for name, mixed, _ in preds:
            normed, total, post = self.pda(self.predictors[name], mixed, dets, lr, t, True)
            lam.append(total)
            posts.append(post)
            normeds.append(normed)
        prod = c * np.asarray(lam)
        mu_post = prod / prod.sum() if idx and prod.sum() > 0 else c
        self.close("IMM mode probabilities", step["post"]["mu"], mu_post, k)
        for i, post in enumerate(posts):
            xi, pi_ = from_ss(post.state_vector, post.covar)
            self.close(f"IMM mode {i} x", step["post"]["modes"][i]["x"], xi, k)
            self.close(f"IMM mode {i} P", step["post"]["modes"][i]["P"], pi_, k)
        b = [self.betas(n, len(z)) for n in normeds]
        beta = [sum(mu_post[i] * b[i][0][j] for i in range(2)) for j in range(len(z))]
        beta0 = sum(mu_post[i] * b[i][1] for i in range(2))
        self.close("IMM beta", step["beta"], beta, k)
        self.close("IMM beta0", [step["beta0"]], [beta0], k)
        xs = StateVectors(np.hstack([np.asarray(post.state_vector, float) for post in posts]))
        ps = np.stack([post.covar for post in posts], axis=2)
        xo, po = gm_reduce_single(xs, ps, mu_post)
        x, p = from_ss(xo, po)
        self.close("IMM posterior x", step["post"]["x"], x, k)
        self.close("IMM posterior P", step["post"]["P"], p, k)
        self.anchor(step, x, beta, t, k)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--tol", type=float, default=1e-9)
    a = ap.parse_args()
    files = sorted(glob.glob(os.path.join(a.dir, "*.json")))
    if not files:
        print(f"no sequences in {a.dir}")
        return 1
    print(f"Stone Soup {stonesoup.__version__}, numpy {np.__version__}; tolerance {a.tol:g}")
    print("| sequence | model | parameters | steps | measurements | gated | largest difference | where |")
    print("|---|---|---|---:|---:|---:|---:|---|")
    failed = False
    for f in files:
        doc = json.load(open(f))
        ch = Checker(doc["params"], a.tol)
        steps = doc["steps"]
        for s in steps:
            if doc["model"] == "imm":
                ch.imm(s)
            else:
                ch.single(doc["model"], s)
        n_z = sum(len(s["z"]) for s in steps)
        n_g = sum(len(s["gated"]) for s in steps)
        bad = ch.worst > a.tol or ch.gate_mismatch > 0
        failed |= bad
        where = ch.where + (f"; {ch.gate_mismatch} gate mismatches" if ch.gate_mismatch else "")
        print(f"| {doc['source']} | {doc['model']} | {doc['set']} | {len(steps)} | {n_z} | {n_g} | {ch.worst:.2e} | {where if bad else 'agrees'} |")
    print("FAILED: disagreement above the tolerance" if failed else "PASSED: every step agrees")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
