#!/usr/bin/python3
"""End-to-end test of the pm INDI math plugin (docs/indi.md, tests/check_indi.c).

indiserver runs INDI 1.9.9's AstroTrac driver in simulation: the shipped
driver that uses the alignment subsystem (indi_simulator_telescope in 1.9.9
does not).  A known mount (an independent gimbal model below, not pm's code)
gives the sync points; INDI's own database loader reads them, plus real Syncs
through the driver; the math plugin is chosen through
ALIGNMENT_SUBSYSTEM_MATH_PLUGINS; GOTOs go through the driver; where the
simulated mount's encoders end up is turned into the place on the sky the
known mount points at, and compared with the target.

The sky stands still (indi/testshim.c freezes libnova's clock in the server and
the driver), and the mount does not track (custom rate 0), so the encoder
readings are exact and timing does not enter.  The driver adds a slew-time
lead to every hour-angle GOTO (AstroTrac::Goto: calculateSlewTime, meant for a
real mount that keeps tracking while it slews, which the simulator does not
model): so each GOTO starts from the target's true encoder position, where the
lead is that of the plugin's own error (0.5" * sqrt(error / 1") in hour angle)
and is included in the reported error, not removed.

Prints "e2e: ..." lines (what tests/check_indi.c reads) and then everything as
one JSON object (the last line); exits 0 when it ran (the caller judges the
numbers), 2 on a failure to run (with the driver's last messages), 77 when
indiserver or the driver is not installed.
"""
import argparse
import ctypes
import json
import re
import math
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from indiclient import Client, IndiError  # noqa: E402

import numpy as np  # noqa: E402

DEV = "AstroTrac"
DRIVER = "indi_astrotrac_telescope"
JD0 = 2460310.25          # the frozen date (2024-01-01 18:00 UT)
LAT, LON = 47.5, 19.0     # site (deg; longitude east)
ARCSEC = 180.0 / math.pi * 3600.0
POLL_S = 0.25             # the driver's polling period (s): 0.75 deg per simulated step
D2R = math.pi / 180.0

# The known mount: an explicit gimbal, in radians (sizeable errors of a
# roughly set-up portable mount), plus tube flexure, which no order-0 model has.
TRUTH = {
    "ha_index": 0.30 * D2R,        # hour-angle encoder zero
    "dec_index": -0.20 * D2R,      # declination encoder zero
    "collimation": 4.0 / 60 * D2R,  # tube not perpendicular to the dec axis
    "nonperp": 2.0 / 60 * D2R,     # dec axis not perpendicular to the polar axis
    "polar_x": 0.25 * D2R,         # polar axis tilted about the E-W axis
    "polar_y": -0.15 * D2R,        # polar axis tilted about the meridian axis
    "flexure": 15.0 / ARCSEC,      # tube sag toward the horizon, times cos(altitude)
    "gear": 0.5 / ARCSEC,          # hour-angle gear error, 3 cycles per turn: beyond pm's order 2
}


class RunError(Exception):
    pass


def rot(axis, a):
    c, s = math.cos(a), math.sin(a)
    if axis == "x":
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    if axis == "y":
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


# Frame: x toward (HA 0, Dec 0), y toward HA -6h (east), z the celestial pole,
# so a direction is (cos d cos h, -cos d sin h, sin d).
def vec(h, d):
    return np.array([math.cos(d) * math.cos(h), -math.cos(d) * math.sin(h), math.sin(d)])


def angles(v):
    v = v / np.linalg.norm(v)
    return math.atan2(-v[1], v[0]), math.asin(max(-1.0, min(1.0, v[2])))


ZENITH = vec(0.0, LAT * D2R)


def truth_sky(h_m, d_m, t=TRUTH):
    """Where the known mount points when its encoders read (h_m, d_m)
    (the hour angle and declination the driver takes them for)."""
    th1, th2 = h_m + t["ha_index"], d_m + t["dec_index"]
    c = t["collimation"]
    # tube in the declination-axis frame (x' meridian, y' dec axis, z' pole)
    tube = np.array([math.cos(c) * math.cos(th2), math.sin(c), math.cos(c) * math.sin(th2)])
    tube = rot("x", t["nonperp"]) @ tube          # dec axis tilted
    tube = rot("z", -th1) @ tube                  # hour-angle rotation (westward)
    v = rot("y", t["polar_y"]) @ rot("x", t["polar_x"]) @ tube
    # gear error: along the hour angle, sin(3 * encoder angle)
    h, _ = angles(v)
    v = v + t["gear"] * math.sin(3 * th1) * np.array([-math.sin(h), -math.cos(h), 0.0])
    # flexure: toward the horizon by F cos(alt)
    s = float(v @ ZENITH)
    up = ZENITH - s * v
    nu = np.linalg.norm(up)
    if nu > 1e-12:
        v = v - t["flexure"] * math.sqrt(max(0.0, 1 - s * s)) * up / nu
    return angles(v)


def sep(h1, d1, h2, d2):
    a, b = vec(h1, d1), vec(h2, d2)
    return math.atan2(np.linalg.norm(np.cross(a, b)), float(a @ b))


def truth_encoders(h, d):
    """The mount position (h_m, d_m) that points at (h, d): Newton on the
    gimbal model with a numerical Jacobian, to 1e-12 rad."""
    x = np.array([h - TRUTH["ha_index"], d - TRUTH["dec_index"]])
    for _ in range(50):
        th, td = truth_sky(*x)
        r = np.array([math.remainder(th - h, 2 * math.pi) * math.cos(d), td - d])
        if np.max(np.abs(r)) < 1e-13:
            return float(x[0]), float(x[1])
        J = np.zeros((2, 2))
        for k in range(2):
            dx = np.zeros(2)
            dx[k] = 1e-7
            th2, td2 = truth_sky(*(x + dx))
            J[:, k] = [math.remainder(th2 - th, 2 * math.pi) * math.cos(d) / 1e-7, (td2 - td) / 1e-7]
        x = x - np.linalg.solve(J, r)
    raise RunError("truth inverse did not converge at h %.3f d %.3f" % (h, d))


def altitude(h, d):
    return math.asin(float(vec(h, d) @ ZENITH))


# The driver's encoder convention (AstroTrac::getEncodersFromRADE, northern
# site, single-arm mount): encoders in degrees.
def encoders_of(h_m, d_m):
    return (h_m / D2R / 15.0 + 6.0) * 15.0, 90.0 - d_m / D2R


def mount_of(ha_enc, de_enc):
    return ((ha_enc / 15.0 - 6.0) * 15.0) * D2R, (90.0 - de_enc) * D2R


def lst_rad():
    """Local apparent sidereal time at JD0, as the driver and the plugin
    compute it (libnova's ln_get_apparent_sidereal_time)."""
    nova = ctypes.CDLL("libnova-0.16.so.0")
    nova.ln_get_apparent_sidereal_time.restype = ctypes.c_double
    nova.ln_get_apparent_sidereal_time.argtypes = [ctypes.c_double]
    return math.remainder(nova.ln_get_apparent_sidereal_time(JD0) * 15 * D2R + LON * D2R, 2 * math.pi)


def ra_hours(lst, h):
    return (lst - h) % (2 * math.pi) / (15 * D2R)


def stop_server(srv):
    """Stop indiserver and its driver (their own process group)."""
    try:
        os.killpg(srv.pid, 15)
    except ProcessLookupError:
        pass
    try:
        srv.wait(timeout=10)
    except subprocess.TimeoutExpired:
        os.killpg(srv.pid, 9)
        srv.wait()


def die_with_parent():
    """In the server's process: SIGTERM when this script dies (Linux)."""
    try:
        ctypes.CDLL(None).prctl(1, 15)   # PR_SET_PDEATHSIG, SIGTERM
    except (OSError, AttributeError):
        pass


def watchdog(srv, deadline, home):
    """Stop the server and exit if the process that started this script goes
    away (a killed test) or the run takes longer than deadline seconds."""
    parent, end = os.getppid(), time.time() + deadline

    def watch():
        while srv.poll() is None:
            if os.getppid() != parent or time.time() > end:
                print("ERROR: %s: server stopped" % ("deadline passed" if time.time() > end else "parent gone"))
                sys.stdout.flush()
                stop_server(srv)
                shutil.rmtree(home, ignore_errors=True)
                os._exit(2)
            time.sleep(1)
    threading.Thread(target=watch, daemon=True).start()


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    p = s.getsockname()[1]
    s.close()
    return p


# -- the sync points ---------------------------------------------------------
def sync_grid():
    pts = []
    for dd in (-25, -5, 15, 35, 55, 75):
        for hh in range(-80, 81, 20):
            h_m, d_m = hh * D2R, dd * D2R
            h, d = truth_sky(h_m, d_m)
            if altitude(h, d) > 15 * D2R:
                pts.append((h_m, d_m, h, d))
    return pts


def write_database(home, pts, lst, extra_bad=False):
    os.makedirs(os.path.join(home, ".indi"), exist_ok=True)
    path = os.path.join(home, ".indi", DEV + "_alignment_database.xml")
    with open(path, "w") as f:
        f.write("<INDIAlignmentDatabase>\n")
        f.write("   <DatabaseReferenceLocation latitude='%.10f' longitude='%.10f'/>\n" % (LAT, LON))
        f.write("   <DatabaseEntries>\n")
        rows = list(pts)
        for i, (h_m, d_m, h, d) in enumerate(rows):
            ra_m = (lst - h_m)  # the mount's RA at JD0, radians
            v = (math.cos(d_m) * math.cos(ra_m), math.cos(d_m) * math.sin(ra_m), math.sin(d_m))
            if extra_bad and i == 3:
                v = (0.0, 0.0, 0.0)   # a malformed entry: no direction
            f.write("      <DatabaseEntry>\n")
            f.write("         <ObservationJulianDate>%.10f</ObservationJulianDate>\n" % JD0)
            f.write("         <RightAscension>%.12f</RightAscension>\n" % ra_hours(lst, h))
            f.write("         <Declination>%.12f</Declination>\n" % (d / D2R))
            for k, c in zip("XYZ", v):
                f.write("         <TelescopeDirectionVector%s>%.17g</TelescopeDirectionVector%s>\n" % (k, c, k))
            f.write("      </DatabaseEntry>\n")
        f.write("   </DatabaseEntries>\n</INDIAlignmentDatabase>\n")
    return path


# -- talking to the driver ---------------------------------------------------
class Mount:
    def __init__(self, c):
        self.c = c

    def encoders(self):
        return self.c.number(DEV, "MOUNT_ENCODERS", "AXIS_RA"), self.c.number(DEV, "MOUNT_ENCODERS", "AXIS_DE")

    def wait_message(self, text, since, timeout):
        """Index of the first driver message containing text after index since."""
        c = self.c

        def found():
            for i in range(since, len(c.messages)):
                if text in c.messages[i][2]:
                    return i + 1
            return False
        return c.wait(found, timeout, "the driver to say '%s'" % text)

    def move_encoders(self, ha_enc, de_enc, timeout=120):
        """Slew to encoder values (MOUNT_ENCODERS: no alignment, no lead) and
        wait until the encoders read them exactly.  The simulator ends a slew
        when it is within 0.1 deg of the target (AstroTrac DIFF_THRESHOLD),
        short of it when the last step happens to stop there: then the
        command is repeated, and from that close the next step lands on it."""
        c = self.c
        want = (round(ha_enc, 6), round(de_enc, 6))   # the driver sends "%f"
        for attempt in range(4):
            since = len(c.messages)
            c.set_number(DEV, "MOUNT_ENCODERS", {"AXIS_RA": want[0], "AXIS_DE": want[1]})
            self.wait_message("Slew complete", since, timeout)
            e = self.encoders()
            if abs(e[0] - want[0]) < 1e-7 and abs(e[1] - want[1]) < 1e-7:
                return want
        raise RunError("the mount did not reach encoders %s after %d commands" % (want, attempt + 1))

    def coord_cmd(self, mode, ra, dec, timeout=120):
        """GOTO (mode TRACK) or SYNC to (ra hours, dec deg).  Returns True
        when the driver accepted it (and, for a GOTO, the slew ended)."""
        c = self.c
        c.set_switch(DEV, "ON_COORD_SET", [mode], [m for m in ("SLEW", "TRACK", "SYNC") if m != mode])
        c.wait(lambda: c.props[(DEV, "ON_COORD_SET")]["values"].get(mode) == "On", 10, "ON_COORD_SET " + mode)
        since = len(c.messages)
        c.set_number(DEV, "EQUATORIAL_EOD_COORD", {"RA": ra, "DEC": dec})
        try:
            i = self.wait_message("Syncing to" if mode == "SYNC" else "Slewing to", since, 3 * POLL_S + 2)
        except IndiError:
            return False   # refused (the plugin could not transform the target)
        if mode == "SYNC":
            return True
        # the encoders the driver commanded (its debug line, 1e-4 deg)
        cmd = None
        self.goto_line = None
        for _, _, t in c.messages[since:i]:
            if "GOTO Sky" in t:
                self.goto_line = t
            mm = re.search(r"GOTO Encoders HA: ([-0-9.]+) \(.*\) DE: ([-0-9.]+)", t)
            if mm:
                cmd = (float(mm.group(1)), float(mm.group(2)))
        self.wait_message("Slew complete", i, timeout)
        self.short = False
        if cmd is not None:
            e = self.encoders()
            if abs(e[0] - cmd[0]) > 1.5e-4 or abs(e[1] - cmd[1]) > 1.5e-4:
                # a slew of several simulator steps stopped within 0.1 deg:
                # finish it at the commanded encoders (to their 1e-4 deg)
                self.short = True
                self.move_encoders(*cmd)
        return True

    def select_plugin(self, name):
        c = self.c
        p = c.prop(DEV, "ALIGNMENT_SUBSYSTEM_MATH_PLUGINS")
        if p is None or name not in p["values"]:
            raise RunError("math plugin '%s' not offered by the driver (offered: %s)" %
                           (name, ", ".join(p["values"]) if p else "none"))
        c.set_switch(DEV, "ALIGNMENT_SUBSYSTEM_MATH_PLUGINS", [name], [k for k in p["values"] if k != name])
        c.wait(lambda: c.props[(DEV, "ALIGNMENT_SUBSYSTEM_MATH_PLUGINS")]["values"].get(name) == "On", 10,
               "plugin %s selected" % name)
        st = c.prop(DEV, "ALIGNMENT_SUBSYSTEM_MATH_PLUGINS")["state"]
        if st == "Alert":
            raise RunError("INDI could not load math plugin '%s' (see the server log)" % name)
        # INDI 1.9.9 initialises a loaded plugin but not the built-in one when
        # it is chosen again: (re)initialise, as a client must.
        c.set_switch(DEV, "ALIGNMENT_SUBSYSTEM_MATH_PLUGIN_INITIALISE", ["ALIGNMENT_SUBSYSTEM_MATH_PLUGIN_INITIALISE"])
        c.wait(lambda: c.props[(DEV, "ALIGNMENT_SUBSYSTEM_MATH_PLUGIN_INITIALISE")]["state"] == "Ok", 10,
               "plugin %s initialised" % name)
        # INDI 1.9.9 leaves a newly loaded plugin believing the mount is
        # alt-az (ZENITH); the driver tells the current plugin the mount's kind
        # when the location is set: set it again.
        since = len(c.messages)
        c.set_number(DEV, "GEOGRAPHIC_COORD", {"LAT": LAT, "LONG": LON, "ELEV": 100.0})
        self.wait_message("Observer location updated", since, 10)


def run(args):
    for exe in ("indiserver", DRIVER):
        if shutil.which(exe) is None:
            print("SKIP: %s not installed (sh tools/deps.sh installs indi-bin)" % exe)
            return 77
    build = os.path.abspath(args.build)
    shim = os.path.join(build, "indi", "libpm_indi_testshim.so")
    plugdir = os.path.join(build, "indi", "MathPlugins")
    for f in (shim, os.path.join(plugdir, "libindi_pm_MathPlugin.so")):
        if not os.path.exists(f):
            raise RunError("%s missing: run make indi first" % f)

    home = tempfile.mkdtemp(prefix="pm-indi-e2e-")
    lst = lst_rad()
    pts = sync_grid()
    env = dict(os.environ, HOME=home, LD_PRELOAD=shim, PM_INDI_FROZEN_JD=repr(JD0),
               PM_INDI_SYSTEM_PLUGIN_DIR=args.plugin_dir, PM_INDI_PLUGIN_DIR=plugdir)
    log_path = os.path.join(build, "indi", "e2e-server.log")
    log = open(log_path, "w")
    result = {"server_log": log_path, "jd": JD0, "site": [LAT, LON],
              "truth": {k: v * ARCSEC for k, v in TRUTH.items()}}
    c = None
    srv = None
    t_start = time.time()
    try:
        # a free port (and a local socket of our own: -u); another process
        # may take the port between the probe and the bind: then again
        for attempt in range(5):
            port = free_port()
            srv = subprocess.Popen(["indiserver", "-v", "-r", "0", "-p", str(port),
                                    "-u", os.path.join(home, "indiserver.sock"), DRIVER],
                                   env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True,
                                   preexec_fn=die_with_parent)
            watchdog(srv, args.deadline, home)
            for _ in range(100):
                try:
                    c = Client("127.0.0.1", port)
                    break
                except OSError:
                    if srv.poll() is not None:
                        break
                    time.sleep(0.1)
            if c is not None:
                time.sleep(0.3)
                if srv.poll() is None:
                    break
                c.close()   # ours exited: that port was someone else's
                c = None
            stop_server(srv)
            srv = None
        if c is None:
            raise RunError("cannot start indiserver on a free port; see %s" % log_path)
        result["port"] = port
        m = Mount(c)
        c.wait_prop(DEV, "SIMULATION", 20)
        c.set_switch(DEV, "SIMULATION", ["ENABLE"], ["DISABLE"])
        c.wait(lambda: c.props[(DEV, "SIMULATION")]["values"].get("ENABLE") == "On", 10, "simulation on")
        c.set_number(DEV, "POLLING_PERIOD", {"PERIOD_MS": POLL_S * 1000})
        c.set_switch(DEV, "CONNECTION", ["CONNECT"], ["DISCONNECT"])
        c.set_switch(DEV, "DEBUG", ["ENABLE"], ["DISABLE"])   # for the "GOTO Encoders" line
        c.wait_prop(DEV, "DEBUG_LEVEL", 10)
        c.set_switch(DEV, "DEBUG_LEVEL", ["DBG_ERROR", "DBG_WARNING", "DBG_SESSION", "DBG_DEBUG"])
        c.wait_prop(DEV, "MOUNT_ENCODERS", 20)
        c.set_number(DEV, "GEOGRAPHIC_COORD", {"LAT": LAT, "LONG": LON, "ELEV": 100.0})
        c.wait(lambda: abs(float(c.props[(DEV, "GEOGRAPHIC_COORD")]["values"]["LAT"]) - LAT) < 1e-9, 10,
               "the site")
        c.set_switch(DEV, "MOUNT_TYPE", ["MOUNT_SINGLE_ARM"], ["MOUNT_GEM"])
        c.set_switch(DEV, "TELESCOPE_TRACK_MODE", ["TRACK_CUSTOM"],
                     ["TRACK_SIDEREAL", "TRACK_SOLAR", "TRACK_LUNAR"])
        c.set_number(DEV, "TELESCOPE_TRACK_RATE", {"TRACK_RATE_RA": 0.0, "TRACK_RATE_DE": 0.0})
        c.set_switch(DEV, "TELESCOPE_PARK", ["UNPARK"], ["PARK"])
        c.wait(lambda: float(c.props[(DEV, "TELESCOPE_TRACK_RATE")]["values"]["TRACK_RATE_RA"]) == 0.0, 10,
               "track rate 0")
        result["plugins_offered"] = list(c.prop(DEV, "ALIGNMENT_SUBSYSTEM_MATH_PLUGINS")["values"])

        # 1) sync points through INDI's own database loader
        # the two points nearest the mount's start (encoders 0, 0: the pole)
        # are synced through the driver, the others loaded
        pts.sort(key=lambda q: max(abs(x) for x in encoders_of(q[0], q[1])))
        write_database(home, pts[2:], lst)
        c.set_switch(DEV, "ALIGNMENT_POINTSET_ACTION", ["LOAD DATABASE"],
                     ["APPEND", "INSERT", "EDIT", "DELETE", "CLEAR", "READ", "READ INCREMENT", "SAVE DATABASE"])
        time.sleep(0.2)
        c.set_switch(DEV, "ALIGNMENT_POINTSET_COMMIT", ["ALIGNMENT_POINTSET_COMMIT"])
        c.wait(lambda: float(c.props[(DEV, "ALIGNMENT_POINTSET_SIZE")]["values"]["ALIGNMENT_POINTSET_SIZE"])
               == len(pts) - 2, 10, "%d sync points loaded" % (len(pts) - 2))
        # 2) two more through the driver's own Sync, at the mount's position
        for h_m, d_m, h, d in pts[:2]:
            m.move_encoders(*encoders_of(h_m, d_m))
            m.coord_cmd("SYNC", ra_hours(lst, h), d / D2R)
        c.wait(lambda: float(c.props[(DEV, "ALIGNMENT_POINTSET_SIZE")]["values"]["ALIGNMENT_POINTSET_SIZE"])
               == len(pts), 10, "%d sync points after two Syncs" % len(pts))
        result["n_sync"] = len(pts)
        result["seconds_setup"] = round(time.time() - t_start, 1)

        # 3) GOTOs with each plugin
        targets = []
        for hh, dd in ((-58, 62), (-64, 28), (-31, 8), (3, 33), (36, 12), (67, 38))[:args.targets]:
            h, d = hh * D2R, dd * D2R
            targets.append((h, d))
        plugins = args.plugins
        errs = {p: [] for p in plugins}
        detail = []
        for h, d in targets:
            h_m, d_m = truth_encoders(h, d)
            start = encoders_of(h_m, d_m)
            row = {"target_ha_deg": h / D2R, "target_dec_deg": d / D2R}
            for p in plugins:
                m.select_plugin(p)
                at = m.move_encoders(*start)
                if not m.coord_cmd("TRACK", ra_hours(lst, h), d / D2R):
                    row[p] = None
                    errs[p].append(float("inf"))
                    continue
                if m.short:
                    row.setdefault("finished_slews", []).append(p)
                row.setdefault("driver", {})[p] = m.goto_line
                lh, ld = truth_sky(*mount_of(*m.encoders()))
                e = sep(lh, ld, h, d) * ARCSEC
                # what a GOTO from the true position would cost with a perfect plugin: 0
                row[p] = e
                errs[p].append(e)
                del at
            detail.append(row)
        result["gotos"] = detail
        result["seconds_gotos"] = round(time.time() - t_start - result["seconds_setup"], 1)
        result["summary"] = {}
        for p in plugins:
            v = np.array(errs[p])
            result["summary"][p] = {"max_arcsec": float(np.max(v)), "rms_arcsec": float(np.sqrt(np.mean(v * v))),
                                    "n": int(len(v))}
        # the plugin's own account of its model
        result["pm_messages"] = sorted(set(t for _, _, t in c.messages if "pm Math Plugin" in t))[-6:]

        # 4) malformed input: a database with a zero direction vector
        m.select_plugin("pm Math Plugin")
        write_database(home, pts, lst, extra_bad=True)
        n_msgs = len(c.messages)
        c.set_switch(DEV, "ALIGNMENT_POINTSET_ACTION", ["LOAD DATABASE"],
                     ["APPEND", "INSERT", "EDIT", "DELETE", "CLEAR", "READ", "READ INCREMENT", "SAVE DATABASE"])
        time.sleep(0.2)
        c.set_switch(DEV, "ALIGNMENT_POINTSET_COMMIT", ["ALIGNMENT_POINTSET_COMMIT"])
        c.wait(lambda: any("skipped" in t for _, _, t in c.messages[n_msgs:]), 10, "the bad sync point reported")
        time.sleep(0.3)
        result["bad_entry_messages"] = [t for _, _, t in c.messages[n_msgs:] if "pm Math Plugin" in t]
        h, d = targets[-1]
        h_m, d_m = truth_encoders(h, d)
        m.move_encoders(*encoders_of(h_m, d_m))
        ok = m.coord_cmd("TRACK", ra_hours(lst, h), d / D2R)
        lh, ld = truth_sky(*mount_of(*m.encoders()))
        result["after_bad_entry_goto_arcsec"] = sep(lh, ld, h, d) * ARCSEC if ok else None
    except (RunError, IndiError):
        if c is not None:
            for t, dv, msg in c.messages[-15:]:
                print("  message: %s" % msg, file=sys.stderr)
            for n in ("EQUATORIAL_EOD_COORD", "MOUNT_ENCODERS", "TELESCOPE_TRACK_STATE"):
                print("  %s: %s" % (n, c.prop(DEV, n)), file=sys.stderr)
        raise
    finally:
        if c is not None:
            c.close()
        if srv is not None:
            stop_server(srv)
        log.close()
        shutil.rmtree(home, ignore_errors=True)
    # plain lines for tests/check_indi.c, then the JSON
    print("e2e: sync_points %d" % result["n_sync"])
    for p in args.plugins:
        v = result["summary"][p]
        refused = sum(1 for r in result["gotos"] if r.get(p) is None)
        print("e2e: plugin '%s' max_arcsec %.6f rms_arcsec %.6f gotos %d refused %d" %
              (p, v["max_arcsec"], v["rms_arcsec"], v["n"], refused))
    for t in result["pm_messages"]:
        print("e2e: model %s" % t)
    print("e2e: bad_entry_reported %d" % any("skipped" in t for t in result["bad_entry_messages"]))
    a = result["after_bad_entry_goto_arcsec"]
    print("e2e: after_bad_entry_arcsec %.6f" % (a if a is not None else -1.0))
    print(json.dumps(result))
    return 0


def default_plugin_dir():
    try:
        lib = subprocess.run(["pkg-config", "--variable=libdir", "libindi"], capture_output=True, text=True,
                             check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        lib = ""
    return os.path.join(lib or "/usr/lib/x86_64-linux-gnu", "indi", "MathPlugins")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--plugin-dir", default=default_plugin_dir(),
                    help="where this INDI looks for math plugins (make indi-e2e passes INDI_PLUGIN_DIR)")
    ap.add_argument("--plugins", nargs="+",
                    default=["pm Math Plugin", "INBUILT_MATH_PLUGIN"],
                    help="plugins to compare (the names INDI offers; all four: docs/indi.md)")
    ap.add_argument("--targets", type=int, default=6, help="GOTO targets (1..6)")
    ap.add_argument("--deadline", type=float, default=840, help="stop everything after this many seconds")
    args = ap.parse_args()
    try:
        return run(args)
    except (RunError, IndiError) as e:
        print("ERROR: %s" % e)
        return 2


if __name__ == "__main__":
    sys.exit(main())
