"""Make the repo root importable however pytest is launched.

`python -m pytest` already puts the current directory on sys.path; the bare
`pytest` entry point does not, so add the repo root once if it is missing.
"""
import sys
from pathlib import Path

REPO_ROOT = str(Path(__file__).resolve().parents[1])
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)
