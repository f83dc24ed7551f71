"""``python -m cpgbiped.envs.cli ...``: the command line."""
import sys

from cpgbiped.envs.cli.main import run

sys.exit(run())
