"""Experiments on a gait: the push envelope (robustness), the phase response (phase_response),
transitions (transition), drive sweeps (sweep), secondary gaits in the body (secondary_check).
"""
