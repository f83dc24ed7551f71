"""The body in physics: the MJCF model and dm_control Physics (biped), rollouts (rollout) and their
compiled tick loop (step_loop), trials and runners for searches (trials), dm_control tasks
(tasks).
"""
