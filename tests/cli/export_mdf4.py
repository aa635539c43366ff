#!/usr/bin/python3
"""Issue 38, item 5 and "It must show" 4: `dynid export` of a stored run, read back by an
independent reader.

  dynid-sim --scenario deploy/scenarios/hill_acceleration.toml    (a 30 s run of the test car)
  dynid-server --store <temp>/store.db ...; dynid-car --replay can.log --fast; dynid close
  dynid export --vehicle dynid-testcar --run export-run --output run.mf4            (every model)
  dynid export ... --format csv --output run.csv
  dynid export ... --model longitudinal_wheel --output wheel.mf4

The MDF4 file is read by a reader written here from the MDF 4.1 block layout (identification,
##HD and its ##MD comment, the ##DG / ##CG / ##CN chains, ##TX names and units, the ##DT records),
never the product's code. The CSV is what the product's own reader (can/mdf4.hpp) made of the same
file. It must show: channels and units equal between the two readers, every value equal to the
last bit, a table per model the run announces, measured - fitted = residual, the file's comment
naming the models; one model with --model; an unknown model refused with the run's models named.

usage: export_mdf4.py BUILD_DIR SOURCE_DIR
Exit 0 pass, 1 fail.
"""
import os
import signal
import struct
import subprocess
import sys
import tempfile

build, source = sys.argv[1:3]
sim_bin = os.path.join(build, "tools", "sim", "dynid-sim")
server_bin = os.path.join(build, "server", "dynid-server")
car_bin = os.path.join(build, "client", "car", "dynid-car")
cli_bin = os.path.join(build, "client", "cli", "dynid")
config = os.path.join(source, "deploy", "cyclonedds", "loopback.xml")
profile = os.path.join(source, "deploy", "profiles", "testcar.toml")
DOMAIN = "40"  # a DDS domain of its own: other e2e tests use 17..39
VEHICLE, RUN = "dynid-testcar", "export-run"
MODELS = ["longitudinal_wheel", "lateral_bicycle", "kinematic_longitudinal", "kinematic_lateral", "clutch_slip",
          "suspension_fl", "suspension_fr", "suspension_rl", "suspension_rr", "tyre_fl", "tyre_fr", "tyre_rl",
          "tyre_rr"]  # the test car's profile


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def read_mdf4(path):
    """{version, comment, groups: [(name, [(channel, unit, values)], times)]} from the block layout."""
    d = open(path, "rb").read()
    if d[0:8] != b"MDF     ":
        fail(f"{path}: identification {d[0:8]!r}")

    def block(at, expect):
        if d[at:at + 4] != b"##" + expect:
            fail(f"offset {at}: {d[at:at + 4]!r} where ##{expect.decode()} was expected")
        length, count = struct.unpack_from("<QQ", d, at + 8)
        links = struct.unpack_from("<%dQ" % count, d, at + 24)
        return links, at + 24 + 8 * count, at + length

    def text(at):
        if at == 0:
            return ""
        kind = d[at + 2:at + 4]
        _, data, end = block(at, kind)
        s = d[data:end].split(b"\0")[0].decode()
        if kind == b"MD":
            s = s[s.index("<TX>") + 4:s.index("</TX>")]
            for entity, c in (("&lt;", "<"), ("&gt;", ">"), ("&quot;", '"'), ("&apos;", "'"), ("&amp;", "&")):
                s = s.replace(entity, c)
        return s

    hd_links, _, _ = block(64, b"HD")
    out = {"version": d[8:16].decode().strip(), "comment": text(hd_links[5]), "groups": []}
    dg = hd_links[0]
    while dg:
        dg_links, dg_data, _ = block(dg, b"DG")
        if d[dg_data] != 0:
            fail(f"##DG at {dg}: record id size {d[dg_data]}, expected 0 (one sorted group)")
        cg_links, cg_data, _ = block(dg_links[1], b"CG")
        if cg_links[0] != 0:
            fail(f"##DG at {dg}: more than one channel group")
        _, cycles, _, _, _, data_bytes, inval = struct.unpack_from("<QQHH4sII", d, cg_data)
        channels, cn = [], cg_links[1]
        while cn:
            cn_links, cn_data, _ = block(cn, b"CN")
            ctype, sync, dtype, bit_off, byte_off, bits = struct.unpack_from("<BBBBII", d, cn_data)
            if dtype != 4 or bits != 64 or bit_off != 0:
                fail(f"##CN at {cn}: data type {dtype}, {bits} bits: expected float64")
            channels.append((text(cn_links[2]), text(cn_links[6]), ctype, sync, byte_off))
            cn = cn_links[0]
        _, dt_data, dt_end = block(dg_links[2], b"DT")
        if dt_end - dt_data != cycles * (data_bytes + inval):
            fail(f"##DT of {text(cg_links[2])}: {dt_end - dt_data} bytes for {cycles} records")
        records = [d[dt_data + k * data_bytes:dt_data + (k + 1) * data_bytes] for k in range(cycles)]
        columns = [(name, unit, [struct.unpack_from("<d", r, off)[0] for r in records])
                   for name, unit, ctype, sync, off in channels]
        masters = [c for c, ch in zip(columns, channels) if ch[2] == 2 and ch[3] == 1]
        if len(masters) != 1 or masters[0][1] != "s":
            fail(f"{text(cg_links[2])}: master channels {[(m[0], m[1]) for m in masters]}")
        out["groups"].append((text(cg_links[2]), [c for c in columns if c is not masters[0]], masters[0][2]))
        dg = dg_links[0]
    return out


def read_csv(path):
    lines = open(path).read().splitlines()
    header = lines[0].split(",")
    rows = {}
    for line in lines[1:]:
        cells = line.split(",")
        rows[float(cells[0])] = cells[1:]
    return header, rows


def dynid(*args, expect=0):
    result = subprocess.run([cli_bin, "--cyclone-config", config, "--domain", DOMAIN, *args], capture_output=True,
                            text=True, timeout=180)
    print("$ dynid " + " ".join(args) + f"  (exit {result.returncode})\n" + result.stdout + result.stderr)
    if result.returncode != expect:
        fail(f"dynid {args[0]} exited {result.returncode}, expected {expect}")
    return result


with tempfile.TemporaryDirectory(prefix="dynid-export-") as tmp:
    subprocess.run([sim_bin, "--scenario", os.path.join(source, "deploy", "scenarios", "hill_acceleration.toml"),
                    "--out", os.path.join(tmp, "run")], check=True, capture_output=True)
    server = subprocess.Popen([server_bin, "--store", os.path.join(tmp, "store.db"), "--cyclone-config", config,
                               "--domain", DOMAIN],
                              stdout=subprocess.DEVNULL, stderr=open(os.path.join(tmp, "server.log"), "w"))
    try:
        car = subprocess.run([car_bin, "--profile", profile, "--cyclone-config", config, "--domain", DOMAIN, "--run",
                              RUN, "--replay", os.path.join(tmp, "run", "can.log"), "--fast", "--spool",
                              os.path.join(tmp, "spool"), "--drain-timeout", "60"],
                             capture_output=True, text=True, timeout=120)
        if car.returncode != 0:
            fail(f"dynid-car exited {car.returncode}: {car.stderr[-2000:]}")
        dynid("close", "--vehicle", VEHICLE, "--run", RUN)
        mf4, csv, wheel = (os.path.join(tmp, n) for n in ("run.mf4", "run.csv", "wheel.mf4"))
        dynid("export", "--vehicle", VEHICLE, "--run", RUN, "--output", mf4)
        dynid("export", "--vehicle", VEHICLE, "--run", RUN, "--format", "csv", "--output", csv)
        dynid("export", "--vehicle", VEHICLE, "--run", RUN, "--model", "longitudinal_wheel", "--output", wheel)
        unknown = dynid("export", "--vehicle", VEHICLE, "--run", RUN, "--model", "longitudinal", "--output",
                        os.path.join(tmp, "none.mf4"), expect=2)
        independent, header, rows = read_mdf4(mf4), *read_csv(csv)
        one = read_mdf4(wheel)
    finally:
        server.send_signal(signal.SIGTERM)
        try:
            server.wait(timeout=30)
        except subprocess.TimeoutExpired:
            server.kill()

if independent["version"] != "4.10":
    fail(f"version {independent['version']}")
groups = independent["groups"]
names = [g[0] for g in groups]
for model in MODELS:
    if not any(n.startswith(model + ".") for n in names):
        fail(f"no table of {model} among {names}")
if "models: " + ", ".join(MODELS) not in independent["comment"]:
    fail(f"the file's comment does not name the models: {independent['comment']!r}")

# Channels and units: the CSV's header (the product's reader) against the independent reader.
expected_header, seen = ["time [s]"], set()
for name, columns, _ in groups:
    for channel, unit, _ in columns:
        if channel not in seen:
            seen.add(channel)
            expected_header.append(f"{channel} [{unit}]" if unit else channel)
if header != expected_header:
    fail(f"CSV header {header}\nindependent reader: {expected_header}")
units = dict(h[:-1].split(" [") for h in expected_header if h.endswith("]"))
for channel, unit in (("vx", "m/s"), ("d_vx", "m/s^2"), ("wheel_torque", "N m"),
                      ("longitudinal_wheel.longitudinal.residual", "N"), ("lateral_bicycle.yaw.fitted", "N m")):
    if units.get(channel) != unit:
        fail(f"{channel}: unit {units.get(channel)!r}, expected {unit!r}")

# Values: every value of every table, to the last bit, and measured - fitted = residual.
compared = 0
for name, columns, times in groups:
    for k, t in enumerate(times):
        if t not in rows:
            fail(f"{name}: time {t!r} is not a row of the CSV")
        for channel, _, values in columns:
            cell = rows[t][header.index(f"{channel} [{units[channel]}]" if channel in units else channel) - 1]
            if float(cell) != values[k]:
                fail(f"{name} {channel} at {t} s: CSV {cell}, independent reader {values[k]!r}")
            compared += 1
    by_name = {c: v for c, _, v in columns}
    measured, fitted, residual = (by_name[f"{name}.{s}"] for s in ("measured", "fitted", "residual"))
    scale = max(abs(v) for v in measured) or 1.0
    worst = max(abs(m - f - r) for m, f, r in zip(measured, fitted, residual))
    if worst > 1e-12 * scale:
        fail(f"{name}: measured - fitted - residual up to {worst} (scale {scale})")
if len(rows) < 300:
    fail(f"{len(rows)} rows in the CSV for a 30 s run on a 12.5 Hz row grid")
print(f"PASS part 1: {len(groups)} tables, {len(expected_header) - 1} channels with units equal between the "
      f"readers, {compared} values equal to the last bit over {len(rows)} times")

if [g[0] for g in one["groups"]] != ["longitudinal_wheel.longitudinal"]:
    fail(f"--model longitudinal_wheel gave tables {[g[0] for g in one['groups']]}")
wheel_columns = {c: v for c, _, v in one["groups"][0][1]}
full = {c: v for c, _, v in groups[names.index("longitudinal_wheel.longitudinal")][1]}
if wheel_columns != full:
    fail("--model longitudinal_wheel's table differs from the same table of the whole export")
if "has no model 'longitudinal'" not in unknown.stderr or "longitudinal_wheel" not in unknown.stderr:
    fail(f"an unknown model's refusal does not name the run's models: {unknown.stderr!r}")
print("PASS")
