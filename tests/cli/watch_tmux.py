#!/usr/bin/python3
"""Issue 16, item 6 and "It must show" 3: `dynid watch --model` in a real terminal during a replay.

  dynid-sim --scenario deploy/scenarios/sine_steer.toml          (a 40 s run of the test car)
  dynid-server --store <temp>/store.db --cyclone-config deploy/cyclonedds/loopback.xml
  tmux: dynid watch --vehicle dynid-testcar --model lateral_bicycle   (a 200 x 60 terminal)
  dynid-car --profile deploy/profiles/testcar.toml --replay can.log --speed 4   (10 s)

While the car replays, the terminal is read (tmux capture-pane) every half second. It must show
one table, redrawn in place: a single header for the model however many revisions arrived, one
line per parameter (value, std, relative std, status, how it moved), the revision growing between
screens. Once the run is closed, the last screen's values and statuses are those of
`dynid --json estimates --model lateral_bicycle`.

usage: watch_tmux.py BUILD_DIR SOURCE_DIR
Exit 0 pass, 1 fail.
"""
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

build, source = sys.argv[1:3]
sim_bin = os.path.join(build, "tools", "sim", "dynid-sim")
server_bin = os.path.join(build, "server", "dynid-server")
car_bin = os.path.join(build, "client", "car", "dynid-car")
cli_bin = os.path.join(build, "client", "cli", "dynid")
config = os.path.join(source, "deploy", "cyclonedds", "loopback.xml")
profile = os.path.join(source, "deploy", "profiles", "testcar.toml")
DOMAIN = "39"  # a DDS domain of its own: other e2e tests use 17..37
VEHICLE, MODEL, RUN = "dynid-testcar", "lateral_bicycle", "watch-run"
PARAMETERS = ["yaw_inertia", "front_cornering_stiffness", "rear_cornering_stiffness"]
HEADER = re.compile(re.escape(f"{VEHICLE} / {MODEL}") + r"  source (\S+), revision (\d+), rows (\d+)")


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def rows_of(screen):
    """parameter -> (value, std, status) from the watch view's lines."""
    out = {}
    for line in screen.splitlines():
        cells = line.split()
        if cells and cells[0] in PARAMETERS and len(cells) >= 5:
            status = " ".join(cells[4:6]) if cells[4] in ("poorly", "not") else cells[4]
            out[cells[0]] = (float(cells[1]), float(cells[2]), status)
    return out


with tempfile.TemporaryDirectory(prefix="dynid-watch-tmux-") as tmp:
    subprocess.run([sim_bin, "--scenario", os.path.join(source, "deploy", "scenarios", "sine_steer.toml"),
                    "--out", os.path.join(tmp, "run")], check=True, capture_output=True)
    socket = os.path.join(tmp, "tmux.sock")
    tmux = ["tmux", "-S", socket]
    server = subprocess.Popen([server_bin, "--store", os.path.join(tmp, "store.db"), "--cyclone-config", config,
                               "--domain", DOMAIN],
                              stdout=subprocess.DEVNULL, stderr=open(os.path.join(tmp, "server.log"), "w"))
    screens = []
    try:
        watch_cmd = [cli_bin, "--cyclone-config", config, "--domain", DOMAIN, "watch", "--vehicle", VEHICLE,
                     "--model", MODEL, "--seconds", "60"]
        # The pane stays after dynid watch ends, so that its last screen can still be read.
        subprocess.run(tmux + ["new-session", "-d", "-s", "watch", "-x", "200", "-y", "60", " ".join(watch_cmd) +
                               "; sleep 120"], check=True)
        time.sleep(1.0)  # the reader joins before the first publication
        car_cmd = [car_bin, "--profile", profile, "--cyclone-config", config, "--domain", DOMAIN, "--run", RUN,
                   "--replay", os.path.join(tmp, "run", "can.log"), "--speed", "4", "--spool",
                   os.path.join(tmp, "spool"), "--drain-timeout", "60"]
        print("$ " + " ".join(car_cmd))
        car = subprocess.Popen(car_cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        while car.poll() is None:
            time.sleep(0.5)
            screens.append(subprocess.run(tmux + ["capture-pane", "-p", "-t", "watch"], capture_output=True,
                                          text=True, check=True).stdout)
        if car.returncode != 0:
            fail(f"dynid-car exited {car.returncode}: {car.stderr[-2000:]}")
        close = subprocess.run([cli_bin, "--cyclone-config", config, "--domain", DOMAIN, "close", "--vehicle", VEHICLE,
                                "--run", RUN], capture_output=True, text=True, timeout=60)
        if close.returncode != 0:
            fail(f"dynid close exited {close.returncode}: {close.stderr}")
        time.sleep(3.0)  # the close's publication reaches the terminal
        final = subprocess.run(tmux + ["capture-pane", "-p", "-t", "watch"], capture_output=True, text=True,
                               check=True).stdout
        estimates = subprocess.run([cli_bin, "--cyclone-config", config, "--domain", DOMAIN, "--json", "estimates",
                                    "--vehicle", VEHICLE, "--run", RUN, "--model", MODEL],
                                   capture_output=True, text=True, timeout=60)
        if estimates.returncode != 0:
            fail(f"dynid estimates exited {estimates.returncode}: {estimates.stderr}")
        table = json.loads(estimates.stdout)["tables"][0]
    finally:
        subprocess.run(tmux + ["kill-server"], capture_output=True)
        server.send_signal(signal.SIGTERM)
        try:
            server.wait(timeout=30)
        except subprocess.TimeoutExpired:
            server.kill()

# During the replay: tables drawn in place, revisions growing.
revisions = []
for screen in screens:
    headers = HEADER.findall(screen)
    if len(headers) > 1:
        fail(f"{len(headers)} headers on one screen: the view scrolls instead of redrawing in place:\n{screen}")
    if headers and headers[0][0] == RUN and len(rows_of(screen)) == len(PARAMETERS):
        revisions.append(int(headers[0][1]))
if len(revisions) < 3:
    fail(f"the table was on screen in {len(revisions)} of {len(screens)} captures during the replay; last:\n"
         + (screens[-1] if screens else "(none)"))
if len(set(revisions)) < 2 or revisions != sorted(revisions):
    fail(f"the revision did not grow from screen to screen: {revisions}")
print(f"during the replay: {len(screens)} screens, the table on {len(revisions)}, "
      f"{len(set(revisions))} revisions, one header each")

# After the close: the last screen is the final table, line for line.
print(final.rstrip())
headers = HEADER.findall(final)
if len(headers) != 1:
    fail(f"{len(headers)} headers on the final screen")
if int(headers[0][1]) != table["revision"]:
    fail(f"final screen at revision {headers[0][1]}, dynid estimates says {table['revision']}")
shown = rows_of(final)
for p in table["parameters"]:
    if p["name"] not in PARAMETERS:
        continue
    value, std, status = shown[p["name"]]
    if abs(value - p["value"]) > 1e-5 * abs(p["value"]) or abs(std - p["std"]) > 1e-5 * abs(p["std"]):
        fail(f"{p['name']}: screen {value} +- {std}, estimates {p['value']} +- {p['std']}")
    if status != p["status"]:
        fail(f"{p['name']}: screen status '{status}', estimates '{p['status']}'")
print("PASS")
