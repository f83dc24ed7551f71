"""What a rollout shows: contact metrics and biomechanics (gait_metrics), the criteria as data
(criteria), the verdicts (validate), the gait matrix (matrix).
"""
