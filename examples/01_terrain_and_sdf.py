"""Load a generated LittleDog course, query heights, build its SDF and ask distances.

Run: python examples/01_terrain_and_sdf.py
"""

import numpy as np

import roughwalk

terrain = roughwalk.load_terrain("round_rocks:seed=4")
print(terrain)

xy = np.array([[0.2, 0.0], [1.0, 0.1], [1.5, -0.2]])
print("heights [m]:", terrain.height(xy).round(4))
print("slopes [deg]:", np.degrees(terrain.slope(xy)).round(1))

sdf = terrain.sdf(resolution=0.005)
points = np.column_stack([xy, terrain.height(xy) + 0.05])  # 5 cm above the ground
d, grad = sdf.query(points)
print("distances 5 cm above the surface [m]:", d.round(4))
print("gradients:", grad.round(3))
