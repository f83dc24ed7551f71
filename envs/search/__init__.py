"""Searches in physics: optimize --physics (physics_search, physics_optimize), cpgbiped tune
(controller_tuning), check-pareto (pareto).
"""
