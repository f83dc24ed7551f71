"""The one controller: its equations (controller), its compiled kernel (control_kernel) and its
gains (gains.json, with their provenance; gains_root.json).
"""
