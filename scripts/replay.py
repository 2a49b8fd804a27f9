#!/usr/bin/env python3
"""rosrun downstream_perception replay.py BAG --config COSTMAP.yaml --out DIR (see
downstream_perception.replay, or --help)."""

import sys

from downstream_perception.replay.cli import main

if __name__ == "__main__":
    sys.exit(main())
