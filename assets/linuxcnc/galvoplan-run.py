#!/usr/bin/python3
"""galvoplan's headless LinuxCNC display: runs one program on this machine and writes a result.

LinuxCNC starts it as the display (`[DISPLAY] DISPLAY`, called with `-ini FILE`). It takes the
program from GALVOPLAN_PROGRAM and writes JSON to GALVOPLAN_RESULT (atomically):
ok, errors, and the times (s) added up by the HAL timers of galvoplan-timers.hal. When it exits,
LinuxCNC shuts down. GALVOPLAN_TIMEOUT_S (default 900) bounds the run.

A streamed on-the-fly job (galvoplan plan ... --stream JOB.stream) also needs its stream:
GALVOPLAN_STREAM. Every sample is checked against the INI's axis limits first (the stream
bypasses LinuxCNC's soft limits): one beyond them and nothing runs. The stream's FIFO is filled
by halstreamer before the program starts and fed while it runs; GALVOPLAN_TRACE names a file
for halsampler's record of what the joints and the laser got, one line per stream period
(X Y U V laser end empty underruns). GALVOPLAN_STREAM_RATE (samples/s) slows the feeder: a
starved stream, for tests.
Written by `galvoplan linuxcnc-config`; runs with the system Python that has LinuxCNC's modules.
"""
import json
import os
import subprocess
import sys
import threading
import time

import linuxcnc

TIMERS = ("t-run", "t-laser", "t-move", "t-laser-move", "t-job")


def ini_path():
    """The INI file LinuxCNC started this display with (`-ini FILE`)."""
    args = sys.argv[1:]
    for i, a in enumerate(args):
        if a == "-ini" and i + 1 < len(args):
            return args[i + 1]
    return os.environ.get("INI_FILE_NAME", "galvoplan.ini")


def check_stream(path, errors):
    """The stream's samples against the INI's axis limits; returns its line count (None when
    a sample is beyond them or a line is malformed: the errors say which)."""
    ini = linuxcnc.ini(ini_path())
    coords = (ini.find("TRAJ", "COORDINATES") or "XYUV").replace(" ", "")
    # the stream's X Y U V: the stage's X and Y, the scanner's two (the last coordinates; a
    # machine's Z, A and B between them stay with motion)
    letters = "XY" + coords[-2:]
    limits = []
    for letter in letters:
        lo = float(ini.find("AXIS_" + letter, "MIN_LIMIT") or "-1e9")
        hi = float(ini.find("AXIS_" + letter, "MAX_LIMIT") or "1e9")
        limits.append((letter, lo, hi))
    n = 0
    with open(path) as f:
        for n, line in enumerate(f, 1):
            cols = line.split()
            try:
                values = [float(c) for c in cols[:4]]
            except ValueError:
                values = []
            if len(values) < 4 or len(cols) < 6:
                errors.append("%s line %d: want X Y U V laser end, got %r" % (path, n, line.strip()))
                return None
            for (letter, lo, hi), v in zip(limits, values):
                if not lo <= v <= hi:
                    errors.append("%s line %d: %s = %s is beyond the machine's limits %s .. %s "
                                  "(the stream bypasses soft limits): not run"
                                  % (path, n, letter, v, lo, hi))
                    return None
    return n


def feed(path, rate):
    """halstreamer fed from `path`, at most `rate` samples a second (0: as fast as it takes
    them); returns the process."""
    streamer = subprocess.Popen(["halstreamer"], stdin=subprocess.PIPE, text=True)

    def run():
        t0 = time.time()
        try:
            with open(path) as f:
                for k, line in enumerate(f):
                    if rate > 0:
                        ahead = k / rate - (time.time() - t0)
                        if ahead > 0:
                            time.sleep(ahead)
                    streamer.stdin.write(line)
            streamer.stdin.close()
        except (BrokenPipeError, ValueError):
            pass

    threading.Thread(target=run, daemon=True).start()
    return streamer


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
    stream = os.environ.get("GALVOPLAN_STREAM", "")
    samples = check_stream(stream, errors) if stream else None
    if stream and samples is None:
        finish(stream_refused=True)

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
    feeder = recorder = None
    if stream:
        rate = float(os.environ.get("GALVOPLAN_STREAM_RATE", "0"))
        feeder = feed(stream, rate)
        # the FIFO full (or the whole stream in it) before the program hands the joints over
        t0 = time.time()
        while rate == 0 and time.time() - t0 < 20 and feeder.poll() is None:
            try:
                depth = int(halcmd("getp", "streamer.0.curr-depth") or 0)
            except ValueError:
                depth = 0
            if depth >= min(samples, 4000):
                break
            time.sleep(0.01)
        trace = os.environ.get("GALVOPLAN_TRACE")
        if trace:
            recorder = subprocess.Popen(["halsampler"], stdout=open(trace, "w"))
    wall0 = time.time()
    command.auto(linuxcnc.AUTO_RUN, 0)
    wait_for(lambda: stat.interp_state != linuxcnc.INTERP_IDLE, 10, "the program to start")
    ended = wait_for(lambda: stat.interp_state == linuxcnc.INTERP_IDLE, timeout_s,
                     "the program to end")
    wall_s = time.time() - wall0
    time.sleep(0.05)
    stat.poll()
    drain()
    stream_result = {}
    if stream:
        time.sleep(0.2)
        for p in (recorder, feeder):
            if p:
                p.terminate()
                p.wait()
        try:
            underruns = int(halcmd("getp", "streamer.0.underruns") or 0)
        except ValueError:
            underruns = None
        stream_ended = halcmd("getp", "streamer.0.pin.5") == "TRUE"
        if not stream_ended:
            errors.append("the stream ran dry before its last sample (%s underruns): E-stop, "
                          "laser off; feed it faster or deepen its FIFO" % underruns)
        stream_result = {"stream_samples": samples, "stream_ended": stream_ended}
    times = {}
    for t in TIMERS:
        try:
            times[t] = float(halcmd("getp", t + ".out"))
        except ValueError:
            times[t] = None
    finish(ok=ended and not errors, wall_s=wall_s, **stream_result, running_s=times["t-run"],
           job_s=times["t-job"], laser_s=times["t-laser"], moving_s=times["t-move"],
           laser_on_moving_s=times["t-laser-move"])


main()
