"""The --seeds argument of the random scene generators (tests/stress/hard_scenes,
tests/coupling_stress): ranges A:B (B excluded) and single seeds, comma-separated."""

import argparse


def parse_seeds(text):
    """'0:16,608,695' -> [0, 1, ..., 15, 608, 695]; an argparse `type`."""
    seeds = []
    for part in text.split(","):
        try:
            if ":" in part:
                a, b = (int(v) for v in part.split(":"))
                if b <= a:
                    raise ValueError
                seeds += range(a, b)
            else:
                seeds.append(int(part))
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"'{part}' in '{text}' is neither a seed nor a range A:B with A < B "
                f"(e.g. 0:16,608)") from None
    return seeds
