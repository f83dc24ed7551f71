"""dm_control tasks: the CPG drives the biped; an agent may add a residual to the controls.

``envs.load(name, **options)`` mirrors ``suite.load``: tasks "walk", "run", "jump", "hop" are
driven by that preset of ``network`` (Morris-Lecar by default: the paper's Table 2), "free" by
the Morris-Lecar weights of an optimiser result (JSON) with its I_app and phi. Every task uses
the one controller (:data:`cpgbiped.envs.control.controller.CONTROL`); the task's name sets only the reward's
target speed.
Action: 8 values in [-1, 1] added to the CPG controller's output (ankle muscles LF, RF, LE,
RE then hips and knees) and clipped to the actuator ranges; a zero action is the pure CPG.
``feedback=K`` closes the loop from the body into the CPG (:mod:`cpg.feedback`).
Reward: upright (torso pitch within 0.3 rad, height above 0.7 m) times forward speed within
the gait's target band (dm_control ``rewards.tolerance``).
"""
from __future__ import annotations

import collections

import numpy as np
from dm_control.rl import control
from dm_control.suite import base
from dm_control.utils import rewards

from cpgbiped.cpg.errors import InputError
from cpgbiped.cpg.network import Network, build

from cpgbiped.envs.simulation.biped import Physics, load_physics
from cpgbiped.envs.control.controller import CONTROL, ControlParams, CPGController, cpg_schedule

TARGET_SPEED = {"walk": 0.5, "run": 1.5, "jump": 0.3, "hop": 0.3}
CONTROL_TIMESTEP = 0.004  # s: 2 physics steps of 2 ms, the control period the gains were tuned at
DEFAULT_TIME_LIMIT = 20.0  # s


class CPGLocomotion(base.Task):
    """A primary gait driven by the 4-cell CPG; all randomness from ``random``."""

    def __init__(self, gait: str, network: Network, params: ControlParams = CONTROL,
                 random=None, random_cpg_state: bool = False, friction_scale: float = 1.0,
                 time_limit: float = DEFAULT_TIME_LIMIT, feedback: float = 0.0):
        super().__init__(random=random)
        from cpgbiped.cpg.feedback import check_gain

        self.feedback = check_gain(network.kind, feedback)
        self.gait, self.network, self.params = gait, network, params
        self.random_cpg_state = random_cpg_state
        self.friction_scale = friction_scale
        self.time_limit = time_limit
        self.controller: CPGController | None = None

    def initialize_episode(self, physics: Physics):
        if self.friction_scale != 1.0 and not getattr(physics, "_friction_scaled", False):
            physics.scale_friction(self.friction_scale)
            physics._friction_scaled = True
        net = self.network
        if self.random_cpg_state:
            net = net.with_state(net.random_state(self.random))
        if self.feedback > 0:  # the network stepped with the physics, one tick per control step
            from cpgbiped.cpg.feedback import loop_network

            loop = loop_network(net, self.feedback, CONTROL_TIMESTEP, self.time_limit + 1.0)
            self.controller = CPGController(physics.model.ptr, physics.data.ptr, None,
                                            self.params, loop=loop)
        else:
            sched = cpg_schedule(net, self.time_limit + 1.0)
            self.controller = CPGController(physics.model.ptr, physics.data.ptr, sched,
                                            self.params)
        super().initialize_episode(physics)

    def before_step(self, action, physics: Physics):
        u = self.controller(physics.data.time) + np.asarray(action, dtype=float)
        lo, hi = physics.model.actuator_ctrlrange.T
        physics.set_control(np.clip(u, lo, hi))

    def action_spec(self, physics):
        from dm_env import specs

        return specs.BoundedArray((8,), np.float64, -np.ones(8), np.ones(8), name="residual")

    def get_observation(self, physics: Physics):
        obs = collections.OrderedDict()
        obs["joint_angles"] = physics.joint_angles()
        obs["torso_height"] = np.array([physics.torso_height()])
        obs["torso_pitch"] = np.array([physics.torso_pitch()])
        obs["com_velocity"] = np.array([physics.com_velocity_x()])
        obs["foot_forces"] = physics.foot_forces()
        c = self.controller
        obs["cpg"] = np.array(c.last_v) if c is not None else np.zeros(4)
        obs["muscle_activation"] = np.array(physics.data.act[:4])
        obs["cpg_feedback"] = c.feedback if c is not None else np.zeros(4)
        return obs

    def get_reward(self, physics: Physics):
        upright = rewards.tolerance(physics.torso_pitch(), bounds=(-0.3, 0.3), margin=0.7)
        standing = rewards.tolerance(physics.torso_height(), bounds=(0.7, 2.0), margin=0.3)
        target = TARGET_SPEED.get(self.gait, 0.5)
        move = rewards.tolerance(physics.com_velocity_x(), bounds=(target, float("inf")),
                                 margin=target, value_at_margin=0.5, sigmoid="linear")
        return float(upright * standing * (1 + 5 * move) / 6)


def load(name: str, weights: str | None = None, network: str = "ml", preset: str | None = None,
         time_limit: float = DEFAULT_TIME_LIMIT, random=None, random_cpg_state: bool = False,
         friction_scale: float = 1.0, xml_path=None, feedback: float = 0.0) -> control.Environment:
    """An environment like ``suite.load``: walk, run, jump, hop, or free (with ``weights``);
    ``feedback``: the gain K of the body's feedback into the CPG (0: open loop; the network is
    then stepped once per control step, :data:`CONTROL_TIMESTEP`)."""
    if name == "free":
        if weights is None:
            raise InputError("task 'free' needs a weights file (an optimiser result JSON)")
        from cpgbiped.cpg.results import load_result

        data = load_result(weights)
        gait = data["gait"]
        net = build("ml", preset or gait, weights=data["chosen"]["weights"], i_app=data["i_app"],
                    phi=data["phi"])
    elif name in TARGET_SPEED:
        gait = name
        net = build(network, preset or name)
    else:
        raise InputError(f"unknown task {name!r}: use walk, run, jump, hop or free")
    if not (np.isfinite(time_limit) and time_limit > 0):
        raise InputError(f"time_limit must be a positive number of seconds, got {time_limit}")
    physics = load_physics(xml_path) if xml_path else load_physics()
    task = CPGLocomotion(gait, net, CONTROL, random=random, random_cpg_state=random_cpg_state,
                         friction_scale=friction_scale, time_limit=time_limit, feedback=feedback)
    return control.Environment(physics, task, time_limit=time_limit,
                               control_timestep=CONTROL_TIMESTEP)
