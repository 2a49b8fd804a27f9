"""python3 -m downstream_perception.replay BAG ... (see cli.DESCRIPTION)."""

import sys

from downstream_perception.replay.cli import main

sys.exit(main())
