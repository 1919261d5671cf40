"""Compares two folders written by scripts/pin_outputs.sh: every file's text with its numbers
taken out must be identical, and every number must agree within 1e-9 relative (1e-12
absolute). Wall-clock figures (keys naming seconds of run time) are skipped. Prints each
difference; exits 1 when there is any."""
import os
import re
import sys

NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")
# Keys (JSON) or labels whose value is the run's own wall-clock time or a timing ratio.
CLOCK = re.compile(r'"(?:[a-z_]*elapsed[a-z_]*|wall[a-z_]*|[a-z_]*_time_s|runtime_s|seconds)"\s*:\s*[-0-9.eE+]+|\b(?:in|took) [0-9.]+ ?(?:s|ms|µs)\b|[0-9.]+ ?ms\b|[0-9.]+ s\b')


def tokens(text: str):
    text = CLOCK.sub("CLOCK", text)
    numbers = [float(m) for m in NUMBER.findall(text)]
    skeleton = NUMBER.sub("#", text)
    return skeleton, numbers


def close(a: float, b: float) -> bool:
    return abs(a - b) <= max(1e-12, 1e-9 * max(abs(a), abs(b)))


def main(a_dir: str, b_dir: str) -> int:
    problems = []
    files = set()
    for root_dir in (a_dir, b_dir):
        for root, _, names in os.walk(root_dir):
            for name in names:
                files.add(os.path.relpath(os.path.join(root, name), root_dir))
    for rel in sorted(files):
        pa, pb = os.path.join(a_dir, rel), os.path.join(b_dir, rel)
        if not os.path.exists(pa) or not os.path.exists(pb):
            problems.append(f"{rel}: only in {'after' if not os.path.exists(pa) else 'before'}")
            continue
        ta = open(pa, encoding="utf-8", errors="replace").read()
        tb = open(pb, encoding="utf-8", errors="replace").read()
        if ta == tb:
            continue
        sa, na = tokens(ta)
        sb, nb = tokens(tb)
        if sa != sb or len(na) != len(nb):
            la, lb = sa.splitlines(), sb.splitlines()
            first = next((i for i in range(min(len(la), len(lb))) if la[i] != lb[i]), min(len(la), len(lb)))
            show_a = la[first][:160] if first < len(la) else "<end>"
            show_b = lb[first][:160] if first < len(lb) else "<end>"
            problems.append(f"{rel}: text differs at line {first + 1}:\n  - {show_a}\n  + {show_b}")
            continue
        worst = max(
            (abs(x - y) / max(abs(x), abs(y), 1e-300) for x, y in zip(na, nb) if not close(x, y)),
            default=None,
        )
        if worst is not None:
            count = sum(1 for x, y in zip(na, nb) if not close(x, y))
            problems.append(f"{rel}: {count} numbers differ, worst relative {worst:.3e}")
    for p in problems:
        print(p)
    print(f"{len(files)} files compared, {len(problems)} differ")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
