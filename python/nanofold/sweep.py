"""``python -m nanofold.sweep SPEC.json``: a sweep described by a JSON file, for clusters
without notebooks (see :func:`nanofold._sweep.main`)."""

from nanofold._sweep import main

if __name__ == "__main__":
    raise SystemExit(main())
