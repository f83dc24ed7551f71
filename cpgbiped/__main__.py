"""``python -m cpgbiped ...``: the command line."""
import sys

from cpgbiped.envs.cli import run

sys.exit(run())
