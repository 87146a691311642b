#!/usr/bin/env python3
"""UMBmark noise study: `odomctl umbmark simulate --noise paper --passes 2` over many seeds.

Prints the spread sigma of the return positions, the one-pass improvement distribution, how
often the 3 x SEM rule asked for a second pass (evaluated on the first verification set) and
what the second pass gained. Usage: tools/umbmark_noise_study.py ODOMCTL [SEEDS] [RUNS]
"""
import json
import statistics
import subprocess
import sys


def main():
    odomctl = sys.argv[1]
    seeds = int(sys.argv[2]) if len(sys.argv) > 2 else 20
    runs = int(sys.argv[3]) if len(sys.argv) > 3 else 5
    rows = []
    for seed in range(1, seeds + 1):
        out = subprocess.run([odomctl, "umbmark", "simulate", "--noise", "paper", "--passes", "2",
                              "--runs", str(runs), "--seed", str(seed), "--json"],
                             check=True, capture_output=True, text=True).stdout
        p1, p2 = json.loads(out)["passes"]
        rows.append({
            "seed": seed,
            "sigma": p1["sigma_before"],
            "before": p1["e_max_syst_before"],
            "after1": p1["e_max_syst_after"],
            "improve1": p1["e_max_syst_before"] / p1["e_max_syst_after"],
            # pass 2's input is pass 1's verification set: its rule decides about pass 2.
            "second_asked": p1["another_pass_recommended"],
            "after2": p2["e_max_syst_after"],
        })
    print("seed  sigma[mm]  Emax before  after 1  improvement  3xSEM asks 2nd?  after 2 [mm]")
    for r in rows:
        print(f"{r['seed']:4d}  {r['sigma']*1e3:8.1f}  {r['before']*1e3:11.1f}  "
              f"{r['after1']*1e3:7.1f}  {r['improve1']:10.1f}x  {str(r['second_asked']):>15}  "
              f"{r['after2']*1e3:11.1f}")
    imp = sorted(r["improve1"] for r in rows)
    q = statistics.quantiles(imp, n=4)
    print(f"sigma: mean {statistics.mean(r['sigma'] for r in rows)*1e3:.1f} mm, "
          f"median {statistics.median(r['sigma'] for r in rows)*1e3:.1f} mm")
    print(f"one-pass improvement: min {imp[0]:.1f}, quartiles {q[0]:.1f} / {q[1]:.1f} / "
          f"{q[2]:.1f}, max {imp[-1]:.1f} (median {statistics.median(imp):.1f}-fold)")
    asked = [r for r in rows if r["second_asked"]]
    print(f"3 x SEM asked for a second pass in {len(asked)} of {len(rows)} seeds")
    for group, name in ((asked, "asked"), ([r for r in rows if not r["second_asked"]], "not asked")):
        if group:
            gain = [r["after1"] / r["after2"] for r in group]
            print(f"  {name}: E_max after 1 pass median {statistics.median(r['after1'] for r in group)*1e3:.1f} mm"
                  f" -> after 2 passes median {statistics.median(r['after2'] for r in group)*1e3:.1f} mm"
                  f" (gain median {statistics.median(gain):.2f}x, range {min(gain):.2f}-{max(gain):.2f}x)")


if __name__ == "__main__":
    main()
