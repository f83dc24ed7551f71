"""``python -m cpgbiped ...``: the command line."""
import sys

from cpgbiped.envs.cli.main import run

sys.exit(run())
