#!/usr/bin/python3
"""galvoplan's headless LinuxCNC display: runs one program on this machine and writes a result.

LinuxCNC starts it as the display (`[DISPLAY] DISPLAY`, called with `-ini FILE`). It takes the
program from GALVOPLAN_PROGRAM and writes JSON to GALVOPLAN_RESULT (atomically):
ok, errors, and the times (s) added up by the HAL timers of galvoplan-timers.hal. When it exits,
LinuxCNC shuts down. GALVOPLAN_TIMEOUT_S (default 900) bounds the run.
Written by `galvoplan linuxcnc-config`; runs with the system Python that has LinuxCNC's modules.
"""
import json
import os
import subprocess
import sys
import time

import linuxcnc

TIMERS = ("t-run", "t-laser", "t-move", "t-laser-move", "t-job")


def main():
    program = os.environ.get("GALVOPLAN_PROGRAM", "")
    result_path = os.environ.get("GALVOPLAN_RESULT", "galvoplan-result.json")
    timeout_s = float(os.environ.get("GALVOPLAN_TIMEOUT_S", "900"))
    result = {"program": program, "ok": False, "errors": []}
    errors = result["errors"]

    def finish(**kw):
        result.update(kw)
        tmp = result_path + ".tmp"
        with open(tmp, "w") as f:
            json.dump(result, f)
        os.replace(tmp, result_path)
        sys.exit(0)

    def halcmd(*args):
        p = subprocess.run(["halcmd", *args], capture_output=True, text=True)
        if p.returncode != 0:
            errors.append("halcmd %s: %s" % (" ".join(args), p.stderr.strip()))
        return p.stdout.strip()

    if not program or not os.path.isfile(program):
        errors.append("no program: set GALVOPLAN_PROGRAM to a G-code file")
        finish()

    stat = linuxcnc.stat()
    command = linuxcnc.command()
    error_channel = linuxcnc.error_channel()

    def drain():
        while True:
            m = error_channel.poll()
            if not m:
                return
            kind, text = m
            if kind in (linuxcnc.NML_ERROR, linuxcnc.OPERATOR_ERROR):
                errors.append(text)

    def wait_for(cond, limit_s, what):
        t0 = time.time()
        while time.time() - t0 < limit_s:
            stat.poll()
            drain()
            if cond():
                return True
            time.sleep(0.002)
        errors.append("timed out after %.0f s waiting for %s" % (limit_s, what))
        return False

    for _ in range(400):
        try:
            stat.poll()
            break
        except linuxcnc.error:
            time.sleep(0.05)
    command.state(linuxcnc.STATE_ESTOP_RESET)
    command.state(linuxcnc.STATE_ON)
    command.wait_complete()
    command.mode(linuxcnc.MODE_MANUAL)
    command.wait_complete()
    command.teleop_enable(0)
    command.wait_complete()
    command.home(-1)
    command.wait_complete()
    if not wait_for(lambda: all(stat.homed[j] for j in range(stat.joints)), 20, "homing"):
        finish()
    command.mode(linuxcnc.MODE_AUTO)
    command.wait_complete()
    command.program_open(program)
    command.wait_complete()
    drain()
    if errors:
        finish()
    halcmd("net", "tm-running", "halui.program.is-running", "tm-run-f.in", "tm-job.in1")
    for t in TIMERS + ("tm-started",):
        halcmd("setp", t + ".reset", "1")
    time.sleep(0.02)
    for t in TIMERS + ("tm-started",):
        halcmd("setp", t + ".reset", "0")
    wall0 = time.time()
    command.auto(linuxcnc.AUTO_RUN, 0)
    wait_for(lambda: stat.interp_state != linuxcnc.INTERP_IDLE, 10, "the program to start")
    ended = wait_for(lambda: stat.interp_state == linuxcnc.INTERP_IDLE, timeout_s,
                     "the program to end")
    wall_s = time.time() - wall0
    time.sleep(0.05)
    stat.poll()
    drain()
    times = {}
    for t in TIMERS:
        try:
            times[t] = float(halcmd("getp", t + ".out"))
        except ValueError:
            times[t] = None
    finish(ok=ended and not errors, wall_s=wall_s, running_s=times["t-run"],
           job_s=times["t-job"], laser_s=times["t-laser"], moving_s=times["t-move"],
           laser_on_moving_s=times["t-laser-move"])


main()
