"""MJCF models shipped with cpgbiped (Menagerie style: one self-contained folder per model)."""
from pathlib import Path

BIPED_DIR = Path(__file__).resolve().parent / "biped"
BIPED_SCENE = BIPED_DIR / "scene.xml"
BIPED_XML = BIPED_DIR / "biped.xml"
