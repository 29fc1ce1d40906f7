import manisoft
import numpy as np

env = manisoft.make_env("ALN", "clean", seed=0, render=True, camera={"width": 128, "height": 128})
obs, info = env.reset(options={"index": 1})  # train scene 1: "Place the shoe at the marker."
print(obs["instruction"], obs["image"].shape)  # the image: uint8 (128, 128, 3)
for _ in range(50):
    action = env.expert_action()  # or your policy's: float (61,) = 20 x 3 element torques, then S
    obs, reward, terminated, truncated, info = env.step(action)
print(info["steps"], info["success"], info["failure"])  # 50 False None
assert info["steps"] == 50 and obs["image"].shape == (128, 128, 3) and np.isfinite(action).all()
