#!/usr/bin/env python3
"""Scores the replies that bench/hbsim/run.sh saved against the hbsim manifest and the rule table
below (a transcription of the "a right answer" column of hbsim's README.md). Python 3 standard
library only.

    score.py [--out DIR] [--clean-seeds N] [--runs REGEX] [--manifest FILE]

Reads DIR/runs/manifest.json and DIR/replies/<run>/ (trace-<model>.json, trace-ref-<model>.json,
consistency.json, estimates.json, timings.tsv); prints the tables and writes DIR/summary.json.

The trace JSON (report/src/residual_report.cpp trace_json): {model, declared, rounds: [{effects,
diagnosis: {verdict, statement, accepted, partial, refused, inseparable, signature: {correlations,
span_start_s, span_end_s, peak_frequency_hz}, candidates}, added: {effect, parameters: [{name,
before, after, reference, ...}]} | null}], added, stopped}.

The first answer of a trace is its first round's diagnosis (the model as the profile declares it):
the term it names as the explanation (`accepted`; with the verdict "explained", or "structure
left" when the term explains a part only), with whether the loop then added it; otherwise its
verdict, with the signature's strongest correlation, the time span holding the most residual and
the spectrum's peak, and the effects it says this run cannot separate.
"""
import argparse
import json
import math
import os
import re
import statistics
import sys

# --------------------------------------------------------------------------------------------
# Matchers over the first round's diagnosis. Each returns (matched, why).


def _first(trace):
    return trace["rounds"][0]["diagnosis"] if trace.get("rounds") else None


def _named(trace):
    """The term the first diagnosis names (its accepted candidate), or None."""
    d = _first(trace)
    return d.get("accepted") if d else None


def _candidate(trace, effect):
    d = _first(trace)
    for c in (d or {}).get("candidates", []):
        if c.get("effect") == effect:
            return c
    return None


def _added_value(trace, effect, parameter):
    """A parameter's value after the first round added `effect` (None if it was not added)."""
    added = trace["rounds"][0].get("added") if trace.get("rounds") else None
    if not added or added.get("effect") != effect:
        return None
    for p in added.get("parameters", []):
        if p.get("name") == parameter:
            return p.get("after")
    return None


def named(pattern, check=None, what=""):
    """The first diagnosis names a term matching `pattern` (and `check(match, trace)` holds)."""
    rx = re.compile(pattern)

    def m(trace, run):
        e = _named(trace)
        if not e:
            return False, ""
        g = rx.fullmatch(e)
        if not g:
            return False, ""
        if check is not None:
            ok, why = check(g, trace, run)
            return ok, f"{e}: {why}"
        return True, e

    m.text = f"names {pattern}" + (f" ({what})" if what else "")
    return m


def structure_left(channels=(), band=None, span_from=None, with_time=False):
    """Verdict "structure left" and its signature points at the listed channels (its strongest
    correlation, the one the statement names, on a listed channel or its derivative d_<channel>),
    or its spectrum peak in `band` (Hz), or its span of most residual starting at or after
    `span_from` x the run's duration."""
    wanted = set(channels) | {"d_" + c for c in channels}

    def m(trace, run):
        d = _first(trace)
        if not d or d.get("verdict") != "structure left":
            return False, ""
        sig = d.get("signature", {})
        cors = sig.get("correlations", [])
        if cors and cors[0].get("channel") in wanted:
            c = cors[0]
            return True, f"structure left, residual correlates with {c['channel']} at {1000 * c['lag_s']:+.0f} ms"
        f = sig.get("peak_frequency_hz")
        if band and f is not None and band[0] <= f <= band[1]:
            return True, f"structure left, spectrum peak {f:.2f} Hz"
        if span_from is not None and sig.get("span_ratio", 0) > 0:
            dur = run["duration_s"]
            if sig.get("span_start_s", 0) >= span_from * dur:
                return True, f"structure left, most in {sig['span_start_s']:.0f}-{sig['span_end_s']:.0f} s of {dur:.0f} s"
        return False, ""

    parts = []
    if channels:
        parts.append("strongest correlation on " + "/".join(channels) + " (or d_)")
    if band:
        parts.append(f"spectrum peak {band[0]}-{band[1]} Hz")
    if span_from is not None:
        parts.append(f"span from {100 * span_from:.0f} % of the run on")
    m.text = "structure left: " + " or ".join(parts)
    return m


def inseparable(effect):
    """The first diagnosis states that `effect` cannot be separated on this run."""

    def m(trace, run):
        d = _first(trace)
        for i in (d or {}).get("inseparable", []):
            if i.get("effect") == effect:
                return True, f"says {effect} cannot be separated"
        return False, ""

    m.text = f"states {effect} cannot be separated"
    return m


def nothing():
    """Nothing added, and the trace ends adequate (a clean run's answer)."""

    def m(trace, run):
        ok = not trace.get("added") and trace["rounds"] and trace["rounds"][-1]["diagnosis"]["verdict"] == "adequate"
        return bool(ok), "adequate, nothing added" if ok else ""

    m.text = "nothing: adequate, nothing added"
    return m


# Checks of a located or fitted value.
def in_range(lo, hi, text):
    """The effect name's first number (a delay in ms, an offset) within [lo, hi]."""
    def c(g, trace, run):
        v = float(g.group(1))
        ok = lo <= v <= hi
        return ok, f"{text(v)} ({'in' if ok else 'outside'} {lo}..{hi})"
    return c


def delay_ms(lo, hi):
    return in_range(lo, hi, lambda v: f"{v:g} ms")


def step_near_event(event_index, seconds):
    def c(g, trace, run):
        t_event = run["events"][event_index][0]
        t = float(g.group(1))
        cand = _candidate(trace, _named(trace)) or {}
        lo, hi = cand.get("located_from_s"), cand.get("located_to_s")
        near = abs(t - t_event) <= seconds
        covers = lo is not None and hi is not None and lo <= t_event <= hi
        coef = cand.get("coefficient")
        return near or covers, (f"at {t:g} s, event {t_event:.1f} s, 95 % set {lo}-{hi} s"
                                + (f", coefficient {coef:.4g} {cand.get('coefficient_unit', '')}" if coef is not None else ""))
    return c


def value_near(parameter, target, tol, fallback_coefficient=True):
    """The named term's fitted value (the parameter after the loop added it; else the screen's
    coefficient of the candidate) within target +- tol."""
    def c(g, trace, run):
        e = g.group(0)
        v = _added_value(trace, e, parameter)
        src = "fitted"
        if v is None and fallback_coefficient:
            v = (_candidate(trace, e) or {}).get("coefficient")
            src = "screen coefficient"
        if v is None:
            return False, "no value"
        ok = abs(v - target) <= tol
        return ok, f"{parameter} = {v:.4g} ({src}; right within {target:g} +- {tol:g})"
    return c


def sign_value(lo, hi):
    """An offset candidate's value (offset:<channel>@<value>) within [lo, hi]."""
    return in_range(lo, hi, lambda v: f"{v:+.3g}")


def any_of(*ms):
    def m(trace, run):
        for x in ms:
            ok, why = x(trace, run)
            if ok:
                return True, why
        return False, ""
    m.text = " | ".join(x.text for x in ms)
    return m


# --------------------------------------------------------------------------------------------
# The rule table: hbsim README.md, "The effect cases", column "a right answer", per case and
# target model (the quoted text is the README's). The tolerances named "ours" are this script's
# reading of "about".
RULES = {
    ("headwind", "longitudinal_wheel"): dict(
        readme="the term linear in v: ... so linear_drag = 5.71 N s/m ...; or a proxy linear in vx (dict:x:vx or "
               "its lags); or the statement that linear_drag cannot be separated from SCx and F_r on this run",
        rule=any_of(named(r"linear_drag"), named(r"dict:(x|lag[123]):vx"), inseparable("linear_drag"))),
    ("headwind", "longitudinal_engine"): "headwind/longitudinal_wheel",
    ("steer_delay", "lateral_bicycle"): dict(
        readme="a delay of the steering channel located at about +80 ms (50-110 ms), e.g. delay:steer@80ms; "
               "first-order proxy: d/dt of steer (dict:d:steer) or its 1-3 sample lags",
        rule=any_of(named(r"delay:steer@\+?(-?[0-9.]+)ms", delay_ms(50, 110), "50-110 ms"),
                    named(r"dict:(d|lag[123]):steer"))),
    ("accel_pitch", "kinematic_longitudinal"): dict(
        readme="an ax offset / mount misalignment named as such (offset:ax, about +0.43 m/s^2), or \"structure "
               "left\" with a signature on ax (or az, pitch_rate). \"Adequate\" with nothing named misses it",
        # "about +0.43": ours, 0.28..0.58 m/s^2 (+-0.15)
        rule=any_of(named(r"offset:ax@\+?(-?[0-9.eE+-]+)", sign_value(0.28, 0.58), "+0.43 +- 0.15 m/s^2, ours"),
                    structure_left(channels=("ax", "az", "pitch_rate")))),
    ("clutch_fade", "clutch_slip"): dict(
        readme="a friction level that drifts with the clutch's dissipated energy (or time, distance): "
               "drift:coulomb_friction or drift:stribeck_friction (~clutch_energy, ~distance); or \"structure left\" "
               "with a signature on time or clutch energy in the later part of the run (40-100 % of it)",
        rule=any_of(named(r"drift:(coulomb|stribeck)_friction(~.*)?"),
                    structure_left(channels=("time", "clutch_energy"), span_from=0.4))),
    ("shuffle", "longitudinal_engine"): dict(
        readme="the engine-side inertia torque, d/dt of engine speed or of gearbox input speed (dict:d:engine_speed, "
               "dict:d:gearbox_input_speed); or \"structure left\" with a signature on engine_speed, "
               "gearbox_input_speed or engine_torque (or their derivatives) or in the 2.3-4.5 Hz band",
        rule=any_of(named(r"dict:d:(engine_speed|gearbox_input_speed)"),
                    structure_left(channels=("engine_speed", "gearbox_input_speed", "engine_torque"),
                                   band=(2.3, 4.5)))),
    ("shuffle", "longitudinal_wheel"): dict(
        readme="**nothing** (its torque is measured after the compliance): adequate, nothing added, estimates as on "
               "a clean run",
        rule=nothing()),
    ("load_drop", "longitudinal_wheel"): dict(
        readme="a step of the mass at the unloading stop: step:mass located within 3 s of 95.7 s (or its 95 % "
               "interval reaching it), about -150 kg. A drift, or a step at another time, is not right",
        rule=named(r"step:mass@([0-9.]+)s", step_near_event(0, 3.0), "within 3 s of the event or its 95 % set")),
    ("load_drop", "longitudinal_engine"): "load_drop/longitudinal_wheel",
    ("ecu_offset", "longitudinal_engine"): dict(
        readme="engine_torque_offset, at -15 N m",
        # "at -15": ours, -15 +- 5 N m
        rule=named(r"engine_torque_offset", value_near("engine_torque_offset", -15.0, 5.0), "-15 +- 5 N m, ours")),
    ("tyre_load", "lateral_bicycle"): dict(
        readme="tyre_saturation (load sensitivity), a dependence of a cornering stiffness on ax or ay "
               "(depends:front_cornering_stiffness~ay and the like), or a product of ax or ay with a slip-angle "
               "channel (steer, vy, yaw_rate); or \"structure left\" with a signature on ax or ay (or their derivatives)",
        rule=any_of(named(r"tyre_saturation"),
                    named(r"depends:(front|rear)_cornering_stiffness~(ax|ay)"),
                    named(r"dict:prod:((ax|ay)\*(steer|vy|yaw_rate)|(steer|vy|yaw_rate)\*(ax|ay))"),
                    structure_left(channels=("ax", "ay")))),
    ("ecu_speed", "clutch_slip"): dict(
        readme="a term in engine speed (dict:x:engine_speed or its lags), about 0.06 N m s/rad, or a product with "
               "engine_speed; the constant part (-0.06 x 200 = -12 N m on the reading) can be taken by the enabled "
               "engine_torque_offset",
        rule=any_of(named(r"dict:(x|lag[123]):engine_speed"), named(r"dict:prod:(.*\*)?engine_speed(\*.*)?"))),
}
# Clean runs and the diagnostic: README "Clean runs (*-cSS): **nothing** on every model: adequate,
# nothing added, estimates within their noise of the truth"; diagnostic: "the right answer is
# nothing, as on a clean run".
CLEAN_RULE = dict(readme="nothing on every model: adequate, nothing added", rule=nothing())


def rule_for(case, model):
    r = RULES.get((case, model))
    if isinstance(r, str):
        r = RULES[tuple(r.split("/"))]
    return r


# --------------------------------------------------------------------------------------------


def load_json(path):
    try:
        with open(path) as f:
            return json.load(f), ""
    except FileNotFoundError:
        return None, "missing"
    except (json.JSONDecodeError, ValueError):
        err = ""
        try:
            with open(path + ".err") as f:
                err = f.read().strip().splitlines()
                err = err[0] if err else ""
        except FileNotFoundError:
            pass
        return None, "no JSON" + (f": {err}" if err else "")


def timings(reply):
    out = {}
    try:
        with open(os.path.join(reply, "timings.tsv")) as f:
            next(f)
            for line in f:
                parts = line.rstrip("\n").split("\t")
                if len(parts) >= 3:
                    out[parts[0]] = {"seconds": float(parts[1]), "exit": int(parts[2])}
    except FileNotFoundError:
        pass
    return out


def first_answer(trace):
    d = _first(trace)
    if d is None:
        return {"text": "no round"}
    r0 = trace["rounds"][0]
    added = (r0.get("added") or {}).get("effect")
    acc = d.get("accepted")
    sig = d.get("signature", {})
    cors = sig.get("correlations", [])
    out = {"verdict": d.get("verdict"), "named": acc, "added": added, "partial": d.get("partial") is not None,
           "masked": bool((d.get("partial") or {}).get("masked")),
           "inseparable": [i.get("effect") for i in d.get("inseparable", [])],
           "refused": [r.get("effect") for r in d.get("refused", [])],
           "signature": {"strongest": (f"{cors[0]['channel']}@{1000 * cors[0]['lag_s']:+.0f}ms" if cors else None),
                         "span_s": [sig.get("span_start_s"), sig.get("span_end_s")],
                         "peak_hz": sig.get("peak_frequency_hz")}}
    if acc:
        text = f"{d['verdict']}: {acc}" + ("" if added == acc else " (not added)")
    elif d.get("verdict") == "structure left":
        s = out["signature"]
        text = (f"structure left [{s['strongest'] or 'no correlation'}; "
                f"{s['span_s'][0]:.0f}-{s['span_s'][1]:.0f} s; {s['peak_hz']:.2f} Hz]")
    else:
        text = d.get("verdict", "?")
    if out["inseparable"]:
        text += " {inseparable: " + ",".join(out["inseparable"]) + "}"
    out["text"] = text
    return out


def key_errors(trace, truth):
    """Per truth parameter of the model: the value before the first added term (the declared fit)
    and after the last, and the errors against the truth. Percent for the parameters with a
    non-zero truth other than a sensor offset (key parameters); absolute for the rest."""
    comps = [r["added"] for r in trace.get("rounds", []) if r.get("added")]
    out = {}
    for name, t in truth.items():
        before = after = None
        if comps:
            for p in comps[0].get("parameters", []):
                if p["name"] == name:
                    before = p.get("before")
            for p in comps[-1].get("parameters", []):
                if p["name"] == name:
                    after = p.get("after")
        key = t != 0 and name != "sensor_offset"
        e = {"truth": t, "before": before, "after": after, "key": key, "unchanged": not comps}
        for side, v in (("before", before), ("after", after)):
            if v is None:
                continue
            if key:
                e[f"err_{side}_pct"] = 100.0 * (v - t) / t
            else:
                e[f"abs_err_{side}"] = v - t
        if key and before is not None and after is not None:
            e["further_pp"] = abs(e["err_after_pct"]) - abs(e["err_before_pct"])
        if comps and before is None and after is None:
            e["absent"] = True  # not a parameter of the model's comparisons
        out[name] = e
    return out


def published_errors(estimates, model, truth):
    for t in (estimates or {}).get("tables", []):
        if t.get("model") == model:
            out = {}
            for p in t.get("parameters", []):
                if p["name"] in truth and truth[p["name"]] != 0 and p["name"] != "sensor_offset" and p.get("value") is not None:
                    out[p["name"]] = 100.0 * (p["value"] - truth[p["name"]]) / truth[p["name"]]
            return out
    return {}


def coverage(estimates, truths):
    """Per published parameter with a truth and the status "identified": (model, name, z) with
    z = (value - truth) / std, the std the table publishes."""
    out = []
    for t in (estimates or {}).get("tables", []):
        truth = truths.get(t.get("model"), {})
        for p in t.get("parameters", []):
            if p["name"] not in truth or p.get("status") != "identified":
                continue
            if p.get("value") is None or not p.get("std"):
                continue
            out.append((t["model"], p["name"], (p["value"] - truth[p["name"]]) / p["std"]))
    return out


def reference_use(ref_trace, args_path):
    """Which --reference names the trace shows with a reference value."""
    given = []
    try:
        with open(args_path) as f:
            given = [a.split("=", 1)[0] for a in re.findall(r"--reference (\S+)", f.read())]
    except FileNotFoundError:
        pass
    shown, params = set(), set()
    comps = [r["added"] for r in ref_trace.get("rounds", []) if r.get("added")]
    for c in comps:
        for p in c.get("parameters", []):
            params.add(p["name"])
            if p.get("reference") is not None:
                shown.add(p["name"])
    return {"given": given, "shown": sorted(shown & set(given)),
            "not_a_parameter": sorted(n for n in given if comps and n not in params),
            "no_comparison": not comps}


def consistency_findings(c):
    if c is None:
        return None
    f = [f"{x['parameter']} {x['model']} vs {x['against']} z={x['z']:+.1f}"
         for x in c.get("comparisons", []) if x.get("significant")]
    f += [f"scale {s['model']} vs {s['against']}: {s.get('off') or 'not one ratio'}"
          for s in c.get("scales", []) if s.get("off") or not s.get("one_ratio")]
    return {"consistent": c.get("consistent"), "findings": f, "left_out": c.get("left_out", []),
            "statement": c.get("statement", "")}


# The simulated sensor noise (1 sigma) of the channels the profile takes from 100 Hz messages, in
# the product's units, transcribed from the hbsim README's bus table: at the grid's 100 Hz each
# grid sample holds one frame's noise, so the product's measured white-noise std should match.
# Channels from 50 Hz or slower messages (vx from the wheel speeds, engine speed, ...) are
# interpolated onto the grid, which changes their noise's colour; they are left out.
SIMULATED_NOISE = {
    "yaw_rate": 0.08 * math.pi / 180.0,          # ChsYawVel 0.08 deg/s
    "ay": 0.03, "ax": 0.03,                      # ChsAccLat, ChsAccLong (m/s^2)
    "vy": 0.02,                                  # OptVy
    "steer": 0.05 * math.pi / 180.0 / 15.5,      # EpsSwAngle 0.05 deg at the hand wheel
    "wheel_torque": 2.0 * math.sqrt(2.0),        # WtmTrqRL + WtmTrqRR, 2 N m each
}
# Messages at 50 Hz, interpolated onto the 100 Hz grid: the white noise at the grid rate with the
# same in-band level is sigma x sqrt(100 / 50) (the level below the cut-off is the message's,
# sigma^2 / 50 per Hz one-sided x 2; the interpolation's fall within the 5 Hz band is 2 %).
SIMULATED_NOISE_50HZ = {
    "vx": 0.02 / 2.0 * math.sqrt(2.0),                             # mean of 4 wheels, 0.02 m/s each
    "wheel_speed_fl": 0.02 * math.sqrt(2.0),
    "engine_speed": 1.5 * 2.0 * math.pi / 60.0 * math.sqrt(2.0),   # EmsEngRpm 1.5 rpm
    "engine_torque": 1.5 * math.sqrt(2.0),                          # EmsTrqAct 1.5 N m
    "gearbox_input_speed": 2.0 * 2.0 * math.pi / 60.0 * math.sqrt(2.0),  # TcuInRpm 2 rpm
    "clutch_clamp_load": 25.0 * math.sqrt(2.0),                    # TcuClutchLoad 25 N
}


def channel_noise(reply):
    """The channel noise the floor used on this run: the first trace's first round."""
    for f in sorted(os.listdir(reply)):
        if f.startswith("trace-") and not f.startswith("trace-ref-") and f.endswith(".json"):
            t, _ = load_json(os.path.join(reply, f))
            if t and t.get("rounds"):
                chans = t["rounds"][0]["diagnosis"].get("floor", {}).get("channels", [])
                return {c["channel"]: c["sigma"] for c in chans if c.get("sigma")}
    return {}


# The floor test's level over a trace's groups (NoiseFloorOptions::error_rate, noise_floor.hpp):
# the JSON gives each group's log_ratio_std, and upper_ratio = exp(z * std), z the normal quantile
# at 1 - this / groups (older replies carry only the latter).
FLOOR_ERROR_RATE = 0.025


def floor_statistics(trace):
    """The first round's floor test per group with rows: z = log(ratio) / its std under "the
    model lacks nothing" (about N(0, 1) on a clean run if the floor and its std are right)."""
    if not trace or not trace.get("rounds"):
        return []
    groups = [g for g in trace["rounds"][0]["diagnosis"].get("floor", {}).get("groups", []) if g.get("rows")]
    quantile = statistics.NormalDist().inv_cdf(1.0 - FLOOR_ERROR_RATE / max(len(groups), 1))
    out = []
    for g in groups:
        if g.get("log_ratio_std", 0) > 0.0 and g.get("ratio", 0) > 0.0:
            out.append(math.log(g["ratio"]) / g["log_ratio_std"])
        elif g.get("upper_ratio", 0) > 1.0 and g.get("ratio", 0) > 0.0:  # replies without the std
            out.append(math.log(g["ratio"]) * quantile / math.log(g["upper_ratio"]))
    return out


def fmt_pct(v):
    return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:+.2f}"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=os.path.join(os.environ.get("TMPDIR", "/tmp"), "dynid-hbsim"))
    ap.add_argument("--clean-seeds", type=int, default=None, help="only clean seeds 1..N (default: all in the manifest)")
    ap.add_argument("--runs", default="", help="only runs matching this regex")
    ap.add_argument("--manifest", default=None)
    args = ap.parse_args(argv)
    manifest_path = args.manifest or os.path.join(args.out, "runs", "manifest.json")
    with open(manifest_path) as f:
        manifest = json.load(f)

    effect_rows, clean_rows, diag_rows, cons_rows, time_rows, ref_rows = [], [], [], [], [], []
    cover_rows = []  # (run, model, parameter, z) of the clean runs' identified published values
    for run in manifest["runs"]:
        name = run["run"]
        if run["kind"] == "clean" and args.clean_seeds is not None and int(name.rsplit("-c", 1)[1]) > args.clean_seeds:
            continue
        if args.runs and not re.search(args.runs, name):
            continue
        reply = os.path.join(args.out, "replies", name)
        if not os.path.isdir(reply):
            continue
        t = timings(reply)
        time_rows.append({"run": name, "timings": t, "noise": channel_noise(reply)})
        models = run["target_models"] if run["kind"] == "effect" else list(run["truth"])
        estimates, _ = load_json(os.path.join(reply, "estimates.json"))
        if run["kind"] == "clean":
            cover_rows.extend((name,) + c for c in coverage(estimates, run["truth"]))
        cons, cons_err = load_json(os.path.join(reply, "consistency.json"))
        cf = consistency_findings(cons)
        cons_rows.append({"run": name, "kind": run["kind"], "case": run["case"],
                          "alarm": None if cf is None else not cf["consistent"],
                          "error": cons_err or None, **(cf or {})})
        for model in models:
            truth = run["truth"].get(model, {})
            trace, err = load_json(os.path.join(reply, f"trace-{model}.json"))
            secs = t.get(f"trace {model}", {}).get("seconds")
            row = {"run": name, "kind": run["kind"], "case": run["case"], "model": model, "seconds": secs}
            if trace is None:
                row.update(error=err, right=False, alarm=None, text=f"ERROR {err}")
            else:
                fa = first_answer(trace)
                final = trace["rounds"][-1]["diagnosis"]["verdict"] if trace.get("rounds") else None
                row.update(first=fa, text=fa["text"], added=trace.get("added", []), final_verdict=final,
                           stopped=trace.get("stopped", ""), errors=key_errors(trace, truth),
                           published_err_pct=published_errors(estimates, model, truth))
                rule = CLEAN_RULE if run["kind"] != "effect" else rule_for(run["case"], model)
                if rule is None:
                    row.update(right=None, why="no rule")
                else:
                    ok, why = rule["rule"](trace, run)
                    row.update(right=ok, why=why, rule=rule["rule"].text, readme=rule["readme"])
                row["alarm"] = bool(trace.get("added")) or final != "adequate"
                row["floor_z"] = floor_statistics(trace)
            ref, ref_err = load_json(os.path.join(reply, f"trace-ref-{model}.json"))
            if ref is not None:
                use = reference_use(ref, os.path.join(reply, f"trace-ref-{model}.args"))
                use.update(run=name, model=model, seconds=t.get(f"trace-ref {model}", {}).get("seconds"),
                           same_added=(trace is not None and ref.get("added") == trace.get("added")))
                ref_rows.append(use)
            elif os.path.exists(os.path.join(reply, f"trace-ref-{model}.args")):
                ref_rows.append({"run": name, "model": model, "error": ref_err})
            {"effect": effect_rows, "clean": clean_rows, "diagnostic": diag_rows}[run["kind"]].append(row)

    # A match through "cannot be separated" (a power statement): how often the same statement is
    # made on the clean traces of the same model, beside it.
    for r in effect_rows:
        g = re.match(r"says (\S+) cannot be separated", r.get("why") or "")
        if g:
            same = [c for c in clean_rows if c["model"] == r["model"] and "first" in c]
            n = sum(1 for c in same if g.group(1) in c["first"].get("inseparable", []))
            r["same_statement_on_clean"] = [n, len(same)]

    # ---- printing ----------------------------------------------------------------------------
    print("== effect cases: the first answer of each trace (first round) against the README's rule")
    print(f"{'case':<12} {'model':<23} {'right':<6} {'s':>6}  first answer / why")
    for r in effect_rows:
        mark = {True: "yes", False: "NO", None: "?"}[r.get("right")]
        secs = f"{r['seconds']:.1f}" if r.get("seconds") is not None else "-"
        print(f"{r['case']:<12} {r['model']:<23} {mark:<6} {secs:>6}  {r['text']}")
        if r.get("why"):
            print(f"{'':<50}  matched: {r['why']}")
            if r.get("same_statement_on_clean"):
                n, m = r["same_statement_on_clean"]
                print(f"{'':<50}  (the same statement is made on {n} of {m} clean traces of this model)")
        if "stopped" in r:
            print(f"{'':<50}  trace added {', '.join(r['added']) or 'nothing'}; stopped: {r['stopped'][:320]}")
            parts = [f"{p} {fmt_pct(e.get('err_before_pct'))} -> {fmt_pct(e.get('err_after_pct'))}"
                     for p, e in r.get("errors", {}).items() if e["key"] and not e["unchanged"] and not e.get("absent")]
            if parts:
                print(f"{'':<50}  error % vs truth, round 0 -> last: " + "; ".join(parts))
    right = sum(1 for r in effect_rows if r.get("right"))

    def clean_table(rows, title):
        print(f"\n== {title}: answer, key parameters' error % against the truth before (round 0) -> after the last round")
        for r in rows:
            secs = f"{r['seconds']:.1f} s" if r.get("seconds") is not None else "-"
            print(f"{r['run']:<30} {r['model']:<23} {'ALARM' if r.get('alarm') else 'ok':<6} {secs:>8}  {r['text']}")
            if r.get("added"):
                print(f"{'':<30}   added {', '.join(r['added'])}; final verdict {r.get('final_verdict')}")
            errs = r.get("errors", {})
            parts = []
            for p, e in errs.items():
                if not e["key"]:
                    continue
                if e.get("absent"):
                    parts.append(f"{p} not a parameter of the trace")
                elif e["unchanged"]:
                    pub = r.get("published_err_pct", {}).get(p)
                    parts.append(f"{p} unchanged (published {fmt_pct(pub)})" if pub is not None
                                 else f"{p} unchanged (not in the published table)")
                else:
                    flag = " FURTHER" if e.get("further_pp", 0) > 2 else ""
                    parts.append(f"{p} {fmt_pct(e.get('err_before_pct'))} -> {fmt_pct(e.get('err_after_pct'))}{flag}")
            if parts:
                print(f"{'':<30}   " + "; ".join(parts))

    clean_table(clean_rows, "clean runs")
    if diag_rows:
        clean_table(diag_rows, "diagnostic (right answer: nothing)")

    print("\n== consistency (dynid consistency, no reference): alarm = not consistent")
    for c in cons_rows:
        status = "ERROR " + c["error"] if c.get("error") else ("ALARM" if c["alarm"] else "ok")
        print(f"{c['run']:<30} {c['kind']:<10} {status:<6}  {'; '.join(c.get('findings') or [])}")

    if ref_rows:
        print("\n== --reference (manifest truth): names the trace shows with a reference value")
        for u in ref_rows:
            if u.get("error"):
                print(f"{u['run']:<30} {u['model']:<23} ERROR {u['error']}")
                continue
            note = "no term added: no comparison shows them" if u["no_comparison"] else (
                "not a parameter of any comparison: " + ",".join(u["not_a_parameter"]) if u["not_a_parameter"] else "all shown")
            secs = f"{u['seconds']:.1f} s" if u.get("seconds") is not None else "-"
            print(f"{u['run']:<30} {u['model']:<23} {secs:>8}  shown {','.join(u['shown']) or '-'}; {note}"
                  f"{'' if u['same_added'] else '; ADDED DIFFERS from the plain trace'}")

    print("\n== channel noise: the floor's measured sigma / the simulated one, over runs")
    for label, table in (("100 Hz", SIMULATED_NOISE), ("50 Hz, as white noise at 100 Hz", SIMULATED_NOISE_50HZ)):
        print(f"   {label}")
        for ch, sim in table.items():
            ratios = sorted(tr["noise"][ch] / sim for tr in time_rows if ch in tr.get("noise", {}))
            if ratios:
                print(f"{ch:<20} median {statistics.median(ratios):.3f}, range {ratios[0]:.3f}-{ratios[-1]:.3f} "
                      f"over {len(ratios)} runs")

    print("\n== the floor test on clean traces (first round): z = log(ratio of squares) / its std, per model")
    print("   (about mean 0, std 1 if the floor and its stated uncertainty hold on this car)")
    by_model = {}
    for r in clean_rows:
        by_model.setdefault(r["model"], []).extend(r.get("floor_z", []))
    for m, zs in by_model.items():
        if len(zs) >= 2:
            print(f"{m:<23} mean {statistics.mean(zs):+.2f}, std {statistics.stdev(zs):.2f} over {len(zs)} groups")

    print("\n== request times (s)")
    for tr in time_rows:
        print(f"{tr['run']:<30} " + ", ".join(f"{k} {v['seconds']:.1f}" + ("" if v["exit"] == 0 else f" (exit {v['exit']})")
                                              for k, v in tr["timings"].items()))

    clean_alarms = [r for r in clean_rows if r.get("alarm")]
    per_model = {}
    for r in clean_rows:
        a = per_model.setdefault(r["model"], [0, 0])
        a[1] += 1
        a[0] += 1 if r.get("alarm") else 0
    clean_cons = [c for c in cons_rows if c["kind"] == "clean"]
    further = [(r["run"], r["model"], p) for r in clean_rows for p, e in r.get("errors", {}).items()
               if e.get("further_pp", 0) > 2]
    trace_secs = [r["seconds"] for r in effect_rows + clean_rows + diag_rows if r.get("seconds") is not None]
    trace_secs += [u["seconds"] for u in ref_rows if u.get("seconds") is not None]
    print()
    print(f"right first answer: {right} of {len(effect_rows)}")
    print(f"false alarms: {len(clean_alarms)} of {len(clean_rows)} clean traces (per model "
          + ", ".join(f"{m} {a[0]}/{a[1]}" for m, a in per_model.items()) + ")")
    print(f"consistency alarms on clean runs: {sum(1 for c in clean_cons if c['alarm'])} of {len(clean_cons)}"
          f" (effect runs {sum(1 for c in cons_rows if c['kind'] == 'effect' and c['alarm'])} of "
          f"{sum(1 for c in cons_rows if c['kind'] == 'effect')}, diagnostic "
          f"{sum(1 for c in cons_rows if c['kind'] == 'diagnostic' and c['alarm'])} of "
          f"{sum(1 for c in cons_rows if c['kind'] == 'diagnostic')})")
    print(f"clean traces ending a key parameter > 2 points further: {len({(a, b) for a, b, _ in further})}"
          + (" (" + "; ".join(f"{a} {b} {p}" for a, b, p in further) + ")" if further else ""))
    if diag_rows:
        print(f"diagnostic traces with an alarm: {sum(1 for r in diag_rows if r.get('alarm'))} of {len(diag_rows)}")
    if trace_secs:
        print(f"trace requests: {len(trace_secs)}, {sum(trace_secs):.0f} s in all, longest {max(trace_secs):.1f} s")
    within = sum(1 for c in cover_rows if abs(c[3]) <= 2.0)
    far = [c for c in cover_rows if abs(c[3]) > 5.0]
    if cover_rows:
        print(f"coverage, clean runs' identified published values: |error| <= 2 std for {within} of {len(cover_rows)}"
              f" ({100.0 * within / len(cover_rows):.0f} %); more than 5 std off: {len(far)}"
              + (" (" + "; ".join(f"{r} {m} {p} z={z:+.1f}" for r, m, p, z in far) + ")" if far else ""))

    summary = {
        "right_first_answer": right, "effect_traces": len(effect_rows),
        "false_alarms": len(clean_alarms), "clean_traces": len(clean_rows),
        "false_alarms_per_model": per_model,
        "consistency_alarms_clean": sum(1 for c in clean_cons if c["alarm"]), "clean_runs": len(clean_cons),
        "clean_traces_further": len({(a, b) for a, b, _ in further}),
        "coverage": {"within_2_std": within, "identified": len(cover_rows), "beyond_5_std": len(far)},
        "effect": effect_rows, "clean": clean_rows, "diagnostic": diag_rows, "consistency": cons_rows,
        "reference": ref_rows, "timings": time_rows,
    }
    with open(os.path.join(args.out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1, default=str)
        f.write("\n")
    print(f"(summary: {os.path.join(args.out, 'summary.json')})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
