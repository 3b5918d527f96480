#!/usr/bin/env python3
"""Path vertices/s as a fraction of the traversal limit (issue 10), in paired rounds.

The limit is Embree's best rate for the path tracer's ray mix in the cornell-area geometry, with
our callbacks (benchmarks/embree_raw_throughput.cpp, its two "vertex mix" rows: the faster one).
On a shared VM the limit itself moves by a third between runs minutes apart, so a fraction is
only meaningful when the limit and Ember's rate are measured back to back. Each round runs

    embree_raw_throughput --rays R --mix-only          (the limit on 1 and on all threads)
    ember bench SCENE --spp S --repeat K --caustics path --threads 1
    ember bench SCENE --spp S --repeat K --caustics path --threads N

and takes the fraction from those three runs alone (the limit's two thread counts are measured
first, so the many-thread pair is some fifteen seconds apart); the rounds' spread is the measurement's
noise. Also reported: per round, the thread scaling (samples/s at N threads over 1 thread); over
all rounds, the best Ember rate over the best limit (best-of-N, the steadier figure when the
host's speed moves within a round).

The same question is also asked of Ember's own rays (columns "own 1t" and "traced"): the batched
kernels time their batches' trace calls inside the render (`ember bench`'s trace_share), which
gives the share of the 1-thread render spent in traversal and callbacks, and the rate at which
Embree traces Ember's own vertices (Ember's rate over that share). The synthetic mix above casts a
shadow ray at every vertex (Ember casts about 0.65 per vertex in cornell-area), has no camera
rays, and starts every ray at a random point of the box, and its timing includes copying rays in
and hits out, where the share times the trace calls alone; Ember's own rays trace faster, and the
share is the stricter fraction.

    benchmarks/limit_fraction.py --ember build-pgo/app/ember \\
        --raw build-pgo/benchmarks/embree_raw_throughput --rounds 8 --json out.json
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def run(command):
    """stdout of a command; its stderr and exit status if it fails."""
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"limit_fraction: {' '.join(command)} failed ({done.returncode}):\n{done.stderr}")
    return done.stdout


def limit(raw, rays, threads):
    """(1-thread limit, all-threads limit) in M path vertices/s: the faster vertex-mix row."""
    out = run([raw, "--rays", str(rays), "--mix-only"])
    # The benchmark's "all threads" are oneTBB's default concurrency; Ember must run as many.
    header = re.search(r"1 thread\s+(\d+) threads", out)
    if not header or int(header.group(1)) != threads:
        sys.exit(f"limit_fraction: {raw} measured {header.group(1) if header else '?'} threads, "
                 f"Ember is asked for {threads} (--threads)")
    rows = [line for line in out.splitlines() if line.startswith("vertex mix")]
    if len(rows) != 2:
        sys.exit(f"limit_fraction: expected two vertex-mix rows from {raw}, got:\n{out}")
    values = [[float(x) for x in re.findall(r"\d+\.\d+", row)[-2:]] for row in rows]
    return max(v[0] for v in values), max(v[1] for v in values)


def bench(ember, scene, spp, repeat, threads, keep=None):
    """(M path vertices/s, samples/s, share of the render spent tracing) of one `ember bench` run
    (the median of its repeats); its JSON is kept at `keep` if given."""
    with tempfile.TemporaryDirectory() as tmp:
        path = keep or os.path.join(tmp, "bench.json")
        run([ember, "bench", scene, "--spp", str(spp), "--repeat", str(repeat), "--caustics", "path",
             "--threads", str(threads), "--json", path])
        with open(path) as f:
            s = json.load(f)["scenes"][0]
    return s["path_vertices_per_second"] * 1e-6, s["samples_per_second"], s["trace_share"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ember", default=os.path.join(ROOT, "build-pgo", "app", "ember"))
    ap.add_argument("--raw", default=os.path.join(ROOT, "build-pgo", "benchmarks", "embree_raw_throughput"))
    ap.add_argument("--scene", default=os.path.join(ROOT, "scenes", "cornell-area.json"))
    ap.add_argument("--rounds", type=int, default=8)
    ap.add_argument("--rays", type=int, default=4_000_000, help="rays per limit measurement")
    ap.add_argument("--spp", type=int, default=64, help="samples per pixel per Ember run")
    ap.add_argument("--repeat", type=int, default=3, help="renders per Ember run (their median counts)")
    ap.add_argument("--threads", type=int, default=len(os.sched_getaffinity(0)),
                    help="the many-thread count: the CPUs this process may run on, as oneTBB counts them")
    ap.add_argument("--json", help="also write every round here")
    ap.add_argument("--keep-bench", metavar="PREFIX",
                    help="keep each round's `ember bench` JSON as PREFIX-t1-K.json and PREFIX-tN-K.json "
                         "(for benchmarks/plot.py)")
    args = ap.parse_args()
    if args.rounds < 1:
        ap.error("--rounds must be at least 1")

    rounds = []
    many = f"{args.threads}t"
    print(f"{'round':>5} {'limit 1t':>9} {'ember 1t':>9} {'fraction':>9} "
          f"{'limit ' + many:>9} {'ember ' + many:>9} {'fraction':>9} {'scaling':>8} {'own 1t':>8} {'traced':>7}")
    for k in range(args.rounds):
        lim1, limN = limit(args.raw, args.rays, args.threads)
        keep = (lambda t: f"{args.keep_bench}-t{t}-{k + 1}.json") if args.keep_bench else (lambda t: None)
        v1, s1, traced1 = bench(args.ember, args.scene, args.spp, args.repeat, 1, keep(1))
        vN, sN, _ = bench(args.ember, args.scene, args.spp, args.repeat, args.threads, keep(args.threads))
        # The same question asked of Ember's own rays: its batches' trace calls, timed in the render,
        # trace its vertices at v1 / traced1; Ember's rate over that is the share itself.
        r = {"limit_1": lim1, "ember_1": v1, "fraction_1": v1 / lim1, "limit_n": limN, "ember_n": vN,
             "fraction_n": vN / limN, "scaling": sN / s1, "own_limit_1": v1 / traced1, "traced_1": traced1}
        rounds.append(r)
        print(f"{k + 1:>5} {lim1:9.2f} {v1:9.2f} {r['fraction_1']:9.1%} {limN:9.2f} {vN:9.2f} "
              f"{r['fraction_n']:9.1%} {r['scaling']:8.2f} {r['own_limit_1']:8.2f} {traced1:7.1%}", flush=True)

    def summary(key):
        values = sorted(r[key] for r in rounds)
        return {"median": statistics.median(values), "min": values[0], "max": values[-1]}

    # On a host whose speed moves within a round, the best rate each side reached is the steadier
    # estimate of what the code can do (the usual best-of-N of noisy timing).
    best = {n: max(r["ember_" + n] for r in rounds) / max(r["limit_" + n] for r in rounds)
            for n in ("1", "n")}
    result = {"best_fraction_1": best["1"], "best_fraction_n": best["n"], "threads": args.threads,
              "spp": args.spp, "repeat": args.repeat, "rays": args.rays, "scene": args.scene, "rounds": rounds,
              "fraction_1": summary("fraction_1"), "fraction_n": summary("fraction_n"),
              "scaling": summary("scaling"), "traced_1": summary("traced_1"),
              "own_limit_1": summary("own_limit_1")}
    for key, name in (("fraction_1", "fraction, 1 thread"), ("fraction_n", f"fraction, {args.threads} threads"),
                      ("scaling", "thread scaling"),
                      ("traced_1", "share of Ember's render in its own rays' traversal, 1 thread"),
                      ("own_limit_1", "traversal rate of Ember's own rays within the render, M vertices/s, 1 thread")):
        s = result[key]
        fmt = "{:.2f}" if key in ("scaling", "own_limit_1") else "{:.1%}"
        print(f"{name}: median {fmt.format(s['median'])} "
              f"(range {fmt.format(s['min'])}-{fmt.format(s['max'])})")
    print(f"best Ember rate over best limit: {best['1']:.1%} on 1 thread, {best['n']:.1%} on {args.threads}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
