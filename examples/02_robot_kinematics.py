"""Load LittleDog, place its feet, solve inverse kinematics and check it with forward kinematics.

Run: python examples/02_robot_kinematics.py
"""

import numpy as np

import roughwalk

robot = roughwalk.load_robot("littledog")
print(robot)
print("legs:", robot.legs, "mass [kg]:", round(robot.mass, 3))

base_pos = np.array([0.0, 0.0, robot.nominal_stance.base_height])
feet = robot.foot_positions(robot.nominal_q, base_pos)
feet[0, 0] += 0.03  # move the left front foot 3 cm forward

q, reachable = robot.inverse_kinematics(feet, base_pos)
print("reachable:", reachable)
print("FK(IK(feet)) error [m]:", np.abs(robot.foot_positions(q, base_pos) - feet).max())
