#!/usr/bin/env python3
"""HHA against HGA on one objective: runs `galvoplan bench` twice (--algo hha, --algo hga) with
the same arguments and prints one Markdown table: the objective per instance (mean ± sd over
the seeds), HGA against HHA in %, the job-time lower bound and the gap HGA leaves to it, and
the ordering times (medians).

usage: scripts/race.py BINARY [bench arguments...]   e.g.
       scripts/race.py target/release/galvoplan ../shared/bench/instances --seeds 5
       scripts/race.py target/release/galvoplan ../shared/bench/instances --seeds 5 --cost distance
"""
import json
import subprocess
import sys
import tempfile


def bench(binary, algo, args):
    with tempfile.NamedTemporaryFile(suffix=".json") as f:
        subprocess.run([binary, "bench", *args, "--algo", algo, "--json", f.name],
                       check=True, stdout=subprocess.DEVNULL)
        return {r["instance"]: r for r in json.load(open(f.name))}


def main():
    binary, args = sys.argv[1], sys.argv[2:]
    distance = "distance" in args
    key, unit, dec = ("idle_mm", "mm", 1) if distance else ("job_time_s", "s", 3)
    hha, hga = bench(binary, "hha", args), bench(binary, "hga", args)
    head = f"| instance | HHA {unit} | HGA {unit} | HGA vs HHA | job LB s | HGA above LB | HHA order ms | HGA order ms |"
    print(head)
    print("|" + "---|" * (head.count("|") - 1))
    for name, a in hha.items():
        b = hga[name]
        ma, mb = a[key]["mean"], b[key]["mean"]
        lb = b.get("job_time_lower_bound_s")
        gap = f"{(b['job_time_s']['mean'] - lb) / lb * 100:+.2f} %" if lb else "–"
        print(f"| {name} | {ma:.{dec}f} ± {a[key]['sd']:.{dec}f} | {mb:.{dec}f} ± {b[key]['sd']:.{dec}f} "
              f"| {(mb - ma) / ma * 100:+.3f} % | {lb:.3f} | {gap} | {a['order_ms']:.0f} | {b['order_ms']:.0f} |"
              if lb else
              f"| {name} | {ma:.{dec}f} ± {a[key]['sd']:.{dec}f} | {mb:.{dec}f} ± {b[key]['sd']:.{dec}f} "
              f"| {(mb - ma) / ma * 100:+.3f} % | – | – | {a['order_ms']:.0f} | {b['order_ms']:.0f} |")


if __name__ == "__main__":
    main()
