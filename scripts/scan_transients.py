"""Scan random initial CPG states for a Morris-Lecar preset whose start-up passes another rhythm.

For each CPG seed, the Table 2 network of ``--gait`` (default walk) is integrated from the
seed's random state and the extensors' overlap over 0.5-3 s of the rollout's clock is printed:
    r = <e_L e_R> / sqrt(<e_L^2> <e_R^2>)
(e: the extensor cells' activations; 1 in phase, 0 never together). The settled walk's is 0;
seeds above --above start in a jump's rhythm. The tuning conditions 21-24 of ``cpgbiped tune``
(envs/search/controller_tuning.py, TRANSIENT_SEEDS) are the seeds this prints with the
defaults:

    python scripts/scan_transients.py            # seeds 1016-1099, r > 0.4
"""
import argparse

from cpgbiped.envs.search.controller_tuning import extensor_overlap


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--gait", default="walk")
    ap.add_argument("--first", type=int, default=1016)
    ap.add_argument("--last", type=int, default=1099)
    ap.add_argument("--above", type=float, default=0.4)
    a = ap.parse_args()
    for seed in range(a.first, a.last + 1):
        r = extensor_overlap(a.gait, seed)
        if r > a.above:
            print(f"seed {seed}: extensor overlap {r:.2f}")


if __name__ == "__main__":
    main()
