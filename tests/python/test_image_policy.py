"""The image + instruction reference policy (examples/python/image_policy.py) on a tiny dataset
written by generate_dataset and rendered by render_dataset: the crop is the table region,
training lowers the loss, the saved model answers as the trained network did, the refinement's
windows and answers are where the camera puts them, the task is told from the instruction, and its
act() drives the end-effector track through evaluate.py from the image alone."""
import json
import os
import shutil
import subprocess
import tempfile
import unittest

import numpy as np
import torch

import evaluate
import image_policy as ip
import reference_policy as rp


class ImagePolicyTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="manisoft_image_policy_")
        cls.data, cls.images = os.path.join(cls.dir, "data"), os.path.join(cls.dir, "images")
        subprocess.run([os.environ["MANISOFT_GENERATE_DATASET"], "--tasks", "ALN", "--clean", "4", "--randomized", "1",
                        "--seed", "0", "--out", cls.data], check=True, stdout=subprocess.DEVNULL)
        subprocess.run([os.environ["MANISOFT_RENDER_DATASET"], cls.data, "--out", cls.images, "--every", "36",
                        "--image-size", "384", "384"], check=True, stdout=subprocess.DEVNULL)
        cls.models = os.path.join(cls.dir, "models")
        cls.args = ["train", "--data", f"{cls.data}:{cls.images}", "--out", cls.models, "--tasks", "ALN", "--epochs", "6",
                    "--batch", "16", "--threads", "1"]
        ip.main(cls.args)
        ip.main(["refine", "--data", f"{cls.data}:{cls.images}", "--perception", cls.models, "--out", cls.models, "--tasks", "ALN",
                 "--epochs", "4", "--batch", "16", "--threads", "1", "--valid-every", "1"])

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def test_the_crop_is_the_table_region_at_the_network_size(self):
        image = np.zeros((192, 192, 3), dtype=np.uint8)
        image[54, 48] = 200  # the crop's top left pixel: (0.25 * 192, 0.28125 * 192)
        self.assertEqual(ip.crop(image).shape, (96, 96, 3))
        self.assertEqual(ip.crop(image)[0, 0, 0], 200)
        big = np.zeros((384, 384, 3), dtype=np.uint8)
        big[108:110, 96:98] = 100  # 2 x 2 pixels averaged into the crop's first
        self.assertEqual(ip.crop(big)[0, 0, 0], 100)
        with self.assertRaisesRegex(ValueError, "100 x 100 image"):
            ip.crop(np.zeros((100, 100, 3), dtype=np.uint8))

    def test_the_camera_maps_points_to_the_crop_and_back(self):
        camera = ip.Camera({"position": [2.0, 0.0, 2.35], "look_at": [0.4, 0.0, 0.95], "up": [0, 0, 1], "fov_y_deg": 60.0,
                            "width": 514, "height": 514})
        # the point looked at is the image's centre: across, the crop's middle; down, 0.5 - 0.28125 of
        # the crop's 0.5 of the image height
        np.testing.assert_allclose(camera.to_crop([0.4, 0.0, 0.95]), [0.0, 2 * (0.5 - 0.28125) / 0.5 - 1], atol=1e-12)
        # a point a tan(30 deg) * depth to the camera's right lies on the image's right edge
        depth = np.linalg.norm(np.array([0.4, 0.0, 0.95]) - [2.0, 0.0, 2.35])
        right = np.array([0.4, 0.0, 0.95]) + np.tan(np.radians(30)) * depth * np.array([0.0, 1.0, 0.0])
        self.assertAlmostEqual(camera.to_crop(right)[0], 2 * (1.0 - 0.25) / 0.5 - 1)
        table = np.array([[0.5, -0.13, 0.75], [0.3, 0.4, 0.9]])
        uv = torch.tensor(np.stack([camera.to_crop(p) for p in table])[None])
        back = camera.on_height(torch, uv, torch.tensor(table[None, :, 2]))
        np.testing.assert_allclose(back[0].numpy(), table, atol=1e-12)

    def test_a_window_is_cut_around_a_point_with_zeros_off_the_image(self):
        image = np.zeros((384, 384, 3), dtype=np.uint8)
        image[108 + 20, 96 + 10] = 7  # the crop's fine pixel (10, 20): the crop starts at (0.25, 0.28125) of 384
        image[108 + 20, 0] = 9  # the image's left column: fine pixel -96
        cut, corner = ip.window(image, (10.5, 20.5), 8)
        self.assertEqual(corner.tolist(), [6, 16])
        self.assertEqual(cut[4, 4, 0], 7)
        self.assertEqual(int(cut[..., 0].sum()), 7)
        cut, corner = ip.window(image, (-95.0, 20.5), 8)  # three columns left of the image
        self.assertEqual(corner.tolist(), [-99, 16])
        self.assertEqual(cut[4, 3, 0], 9)
        self.assertEqual(int(cut[:, :3].sum()), 0)
        with self.assertRaisesRegex(ValueError, "refinement reads the crop at 192 x 192 pixels; a 192 x 192 image's is 96 x 96"):
            ip.window(np.zeros((192, 192, 3), dtype=np.uint8), (0.0, 0.0), 8)

    def test_refinement_lowers_its_loss_and_answers_through_the_camera_ray(self):
        saved = torch.load(os.path.join(self.models, "ALN.refine.pt"))
        losses = [train for _, train, _, _ in saved["history"]]
        self.assertLess(losses[-1], 0.5 * losses[0], losses)
        loaded = ip.Perception(os.path.join(self.models, "ALN.perception.pt"), torch)
        self.assertIsNotNone(loaded.refiner)
        _, image, _, _, said, _, camera = next(ip.episode_frames([f"{self.data}:{self.images}"], "ALN"))
        instruction = said[0]
        tokens, offsets = ip.encode(torch, [instruction], loaded.vocabulary)
        with torch.no_grad():
            first = loaded.model(torch.from_numpy(ip.crop(image)[None]), tokens, offsets)[0].numpy()
        uv = np.stack([first[ip.ANSWER + 2 * ip.POINTS.index(n):ip.ANSWER + 2 * ip.POINTS.index(n) + 2] for n in loaded.refiner.points])
        fine, z, heading = ip.refine(torch, loaded.refiner, [image], uv[None], tokens, offsets)
        y, _ = loaded(image, instruction)
        for kind, name in enumerate(loaded.refiner.points):
            # the refined point lies on the camera ray through its crop coordinates, at its height
            c = ip.FIELDS[name][0]
            np.testing.assert_allclose(camera.to_crop(y[c:c + 3]), fine[0, kind], atol=1e-9)
            self.assertAlmostEqual(y[c + 2], z[0, kind], places=9)
        # the marker is upright, turned by the refined heading
        c = ip.FIELDS["second_rotation"][0]
        np.testing.assert_allclose(y[c:c + 6], [np.cos(heading[0]), np.sin(heading[0]), 0, -np.sin(heading[0]), np.cos(heading[0]), 0],
                                   atol=1e-12)
        # the rest of the answer is the first stage's
        np.testing.assert_allclose(y[ip.FIELDS["width"][0]], first[ip.FIELDS["width"][0]], atol=1e-6)
        # the held-out errors: the first stage's end effector error recomputed here
        frames = list(ip.episode_frames([f"{self.data}:{self.images}"], "ALN"))[:12]
        valid = {"images": [f[1] for f in frames], "answers": [f[2] for f in frames], "instructions": [f[4][0] for f in frames],
                 "resting": [f[5] for f in frames]}
        errors = ip.refined_errors(torch, loaded, loaded.refiner, valid, loaded.rest_height)
        self.assertEqual(set(errors), {"marker heading", "ee_position", "object_position", "object_position at rest", "second_position"})
        tokens, offsets = ip.encode(torch, valid["instructions"], loaded.vocabulary)
        with torch.no_grad():
            out = loaded.model(torch.from_numpy(np.stack([ip.crop(i) for i in valid["images"]])), tokens, offsets).numpy()
        ee = np.linalg.norm(out[:, 0:3] - np.asarray(valid["answers"])[:, 0:3], axis=1)
        self.assertAlmostEqual(errors["ee_position"]["first stage"][0], float(np.median(ee)), places=5)
        # a refinement trained beside another first stage is refused, naming the files
        other = os.path.join(self.dir, "other_refine")
        os.makedirs(other, exist_ok=True)
        shutil.copy(os.path.join(self.models, "ALN.perception.pt"), other)
        saved["vocabulary"] = {"another": 1}
        torch.save(saved, os.path.join(other, "ALN.refine.pt"))
        with self.assertRaisesRegex(ValueError, "ALN.refine.pt: trained beside another perception model"):
            ip.Perception(os.path.join(other, "ALN.perception.pt"), torch)

    def test_heat_map_cells_of_points(self):
        # the crop's 96 pixels in 24 cells of 4: (0, 0) is pixel 48 across and down, cell 12 of each;
        # the top left corner is cell 0; a point off the crop is ignored (-100)
        points = torch.tensor([[0.0, 0.0, -1.0, -1.0, 1.5, 0.0, 0.0, 0.99]])
        self.assertEqual(ip.cells_of(torch, points).tolist(), [[12 * 24 + 12, 0, -100, 23 * 24 + 12]])

    def test_training_lowers_the_loss_and_the_saved_model_answers_the_same(self):
        saved = torch.load(os.path.join(self.models, "ALN.perception.pt"))
        losses = [train for _, train, _, _ in saved["history"]]
        self.assertEqual(len(losses), 6)
        self.assertLess(losses[-1], 0.5 * losses[0], losses)
        # the labels are the recorded state at the frames' steps: the goal marker's pose of the scene
        frames = ip.read_frames([f"{self.data}:{self.images}"], "ALN")["train"]
        self.assertGreater(len(frames["images"]), 20)
        trained = ip.build_model(torch, len(saved["vocabulary"]), len(saved["assets"]), ip.Camera(saved["camera"]))
        trained.load_state_dict(torch.load(os.path.join(self.models, "ALN.perception.pt.checkpoint"))["model"])
        trained.eval()
        loaded = ip.Perception(os.path.join(self.models, "ALN.perception.pt"), torch)
        tokens, offsets = ip.encode(torch, [frames["instructions"][0][0]], loaded.vocabulary)
        image = torch.from_numpy(frames["images"][0][None])
        with torch.no_grad():
            self.assertTrue(torch.equal(trained(image, tokens, offsets), loaded.model(image, tokens, offsets)))

    def test_a_stopped_run_resumes_to_the_uninterrupted_weights(self):
        parts = os.path.join(self.dir, "parts")
        args = [a if a != self.models else parts for a in self.args]
        ip.main(args + ["--stop-after", "2"])
        self.assertFalse(os.path.exists(os.path.join(parts, "ALN.perception.pt")))
        ip.main(args + ["--resume"])
        a, b = torch.load(os.path.join(self.models, "ALN.perception.pt")), torch.load(os.path.join(parts, "ALN.perception.pt"))
        self.assertEqual(a["history"], b["history"])
        for k in a["model"]:
            self.assertTrue(torch.equal(a["model"][k], b["model"][k]), k)

    def test_images_of_another_dataset_are_refused_by_name(self):
        other = os.path.join(self.dir, "other_images")
        os.makedirs(other, exist_ok=True)
        shutil.copy(os.path.join(self.images, "demo_0.hdf5"), os.path.join(other, "demo_99.hdf5"))
        with self.assertRaisesRegex(ValueError, "demo_99.hdf5: demo_99 is not in .*dataset.hdf5"):
            ip.read_frames([f"{self.data}:{other}"], "ALN")

    def test_labels_are_the_recorded_state(self):
        scene = {"task": "ALN", "goal": {"object": 0, "goal_pose": {"position": [0.3, 0.4, 0.75], "rotation": np.eye(3).tolist()}},
                 "objects": [{"asset_id": "shoe"}], "obstacles": []}
        eef = np.array([0.1, 0.2, 0.9, 1.0, 0.0, 0.0, 0.0])
        obj = np.array([[0.5, -0.1, 0.8, 0.0, 0.0, 0.0, 1.0]])  # turned a half turn about z
        y, asset = ip.labels_of(scene, eef, np.array([0.04, 1.0]), obj)
        self.assertEqual(asset, "shoe")
        np.testing.assert_allclose(y[0:3], [0.1, 0.2, 0.9])
        np.testing.assert_allclose(y[3:9], [1, 0, 0, 0, 1, 0])
        self.assertAlmostEqual(y[9], 0.04)
        np.testing.assert_allclose(y[10:19], [0.5, -0.1, 0.8, -1, 0, 0, 0, -1, 0], atol=1e-12)
        np.testing.assert_allclose(y[19:22], [0.3, 0.4, 0.75])
        np.testing.assert_allclose(ip.rotation_of_six(y[13:19]), np.diag([-1.0, -1.0, 1.0]), atol=1e-12)

    def test_the_task_is_told_from_the_instruction(self):
        a = ip.Perception(os.path.join(self.models, "ALN.perception.pt"), torch)
        b = ip.Perception.__new__(ip.Perception)
        b.counts = {"put": 5, "into": 5, "the": 10, "basket": 5}
        models = {"ALN": a, "COLL": b}
        self.assertEqual(ip.task_of("Place the shoe at the marker.", models), "ALN")
        self.assertEqual(ip.task_of("Put it into the basket, please.", models), "COLL")

    def test_the_head_adapted_to_perception_trains_on_what_acting_reads(self):
        heads, adapted = os.path.join(self.dir, "adapt_heads"), os.path.join(self.dir, "adapted")
        rp.main(["train", "--data", self.data, "--out", heads, "--tasks", "ALN", "--epochs", "2", "--batch", "64", "--width", "64",
                 "--stride", "8", "--threads", "1"])
        pairs = [f"{self.data}:{self.images}"]
        perception = ip.Perception(os.path.join(self.models, "ALN.perception.pt"), torch)
        head = torch.load(os.path.join(heads, "ALN.pt"))
        rows, counts = ip.perceived_rows(ip.perceived_reads(pairs, "ALN", perception, 36), perception, head)
        self.assertEqual(counts["train"] + counts["valid"], 5)
        self.assertEqual(len(list(ip.perceived_reads(pairs, "ALN", perception, 36, ("randomized",)))), 1)  # of 4 clean, 1 randomized
        # each row: what act() hands the head for that frame, the frames read one at a time in order
        # (the resting object until the expert's command closes the gripper; the previous command and
        # its age the expert's), and the label the privileged training's row at that step
        mask, scene, a, frames, steps, said, _ = next(ip.rendered_episodes(pairs, "ALN"))
        self.assertEqual(mask, "train")
        np.testing.assert_array_equal(steps, np.arange(len(steps)) * 36)
        xs, ys = rp.samples_of((mask, scene, a), 36, 36, head["assets"])
        self.assertEqual(len(xs), len(frames))
        perception.reset()
        closed = False
        for i, frame in enumerate(frames):
            previous = rp.home_command(a["eef_pose"][0, :3]) if i == 0 else a["ee_target"][steps[i] - 36]
            closed = closed or previous[6] >= 0.5
            y, asset = perception(frame, said[0], resting=not closed)
            seen, roles = ip.seen_observation(perception, y, asset, float(previous[6] >= 0.5), previous if i else None)
            x = rp.observed_features(seen, roles, (previous, np.zeros(7), np.zeros(3), 0, 0), head["assets"])
            # the end effector where seen_observation puts it, width, S and the previous command from it; the label
            np.testing.assert_allclose(rows["train"][0][i, :13], x[:13].astype(np.float32), atol=1e-4)
            np.testing.assert_allclose(rows["train"][1][i], ys[i].astype(np.float32), atol=1e-6)
        # the adapted model starts from the privileged one and lowers the loss on these rows
        ip.main(["adapt", "--data", pairs[0], "--perception", self.models, "--reference", heads, "--out", adapted, "--tasks", "ALN",
                 "--epochs", "4", "--batch", "16", "--lr", "1e-3", "--threads", "1"])
        saved = torch.load(os.path.join(adapted, "ALN.head.pt"))
        norm = rp.Normaliser.of_state(head["norm"]).constant_in_own_units()
        self.assertEqual((saved["norm"], saved["assets"], saved["repeat"]), (norm.state(), head["assets"], head["repeat"]))
        losses = [train for _, train, _ in saved["history"]]
        model = rp.build_model(torch, head["inputs"], head["width"], head["depth"])
        model.load_state_dict(head["model"])
        x, y = rows["train"]
        with torch.no_grad():
            before = rp.loss_of(torch, model(torch.from_numpy(norm(x))), torch.from_numpy(x), torch.from_numpy(y)).item()
        self.assertLess(losses[-1], 0.7 * before, (before, losses))
        # acting, the adapted head beside the perception is used: no reference models needed
        for name in ("ALN.perception.pt", "ALN.refine.pt"):
            shutil.copy(os.path.join(self.models, name), adapted)
        saved_env = {k: os.environ.pop(k, None) for k in ("MANISOFT_REFERENCE_MODELS", "MANISOFT_PERCEPTION_MODELS")}
        os.environ["MANISOFT_PERCEPTION_MODELS"] = adapted
        ip._perception.clear()
        ip._heads.clear()
        try:
            out = os.path.join(self.dir, "eval_adapted")
            self.assertEqual(evaluate.main(["--task", "ALN", "--setting", "clean", "--policy", "python:image_policy:act",
                                            "--action-mode", "ee_pose", "--image-size", "384", "384", "--indices", "0",
                                            "--out", out]), 0)
            with open(os.path.join(out, "episodes.jsonl")) as f:
                episode = json.loads(f.readline())
            self.assertNotIn(episode["failure"], ("policy_error", "bad_action", "policy_timeout"), episode)
        finally:
            ip._perception.clear()
            ip._heads.clear()
            for k, v in saved_env.items():
                os.environ.pop(k, None)
                if v is not None:
                    os.environ[k] = v
        # frames not every repeat control steps are refused, saying how to render them
        with self.assertRaisesRegex(ValueError, "acts every 72 control steps from step 0; render with render_dataset --every 72"):
            next(ip.perceived_reads(pairs, "ALN", perception, 72))

    def test_evaluate_runs_it_from_the_image_on_the_end_effector_track(self):
        heads = os.path.join(self.dir, "heads")
        rp.main(["train", "--data", self.data, "--out", heads, "--tasks", "ALN", "--epochs", "3", "--batch", "64", "--width", "64",
                 "--stride", "8", "--threads", "1"])
        os.environ["MANISOFT_REFERENCE_MODELS"], os.environ["MANISOFT_PERCEPTION_MODELS"] = heads, self.models
        out = os.path.join(self.dir, "eval")
        code = evaluate.main(["--task", "ALN", "--setting", "clean", "--policy", "python:image_policy:act", "--action-mode", "ee_pose",
                              "--image-size", "384", "384", "--indices", "0", "--out", out])
        self.assertEqual(code, 0)
        with open(os.path.join(out, "episodes.jsonl")) as f:
            episodes = [json.loads(line) for line in f if line.strip()]
        self.assertEqual(len(episodes), 1)
        # a model this small fails the episode; it must fail it by the task, never by the policy
        self.assertNotIn(episodes[0]["failure"], ("policy_error", "bad_action", "policy_timeout"), episodes[0])
        self.assertGreater(episodes[0]["steps"], 36)


class SeenObservationTest(unittest.TestCase):
    def test_the_end_effector_is_taken_on_its_ray_nearest_the_last_command_when_close(self):
        # a camera 1 m above the origin: the ray through a perceived end effector at the origin is the
        # z axis; the command's nearest point on it is the command's height
        perception = type("P", (), {"task": "ALN", "model_camera": type("C", (), {"position": np.array([0.0, 0.0, 1.0])})()})()
        y = np.zeros(ip.ANSWER)
        y[3:9] = [1, 0, 0, 0, 1, 0]
        y[13:19] = y[22:28] = [1, 0, 0, 0, 1, 0]
        command = np.array([0.03, -0.02, 0.05, 0, 0, 0, 0])
        seen, _ = ip.seen_observation(perception, y, "shoe/00", 0.0, command)
        np.testing.assert_allclose(seen["end_effector"][:3, 3], [0.0, 0.0, 0.05], atol=1e-12)
        command[2] = ip.NEAR + 0.01  # its nearest point farther than NEAR from the perceived one: kept
        seen, _ = ip.seen_observation(perception, y, "shoe/00", 0.0, command)
        np.testing.assert_allclose(seen["end_effector"][:3, 3], [0.0, 0.0, 0.0])
        seen, _ = ip.seen_observation(perception, y, "shoe/00", 0.0, None)  # before the first command
        np.testing.assert_allclose(seen["end_effector"][:3, 3], [0.0, 0.0, 0.0])

    def test_columns_constant_in_training_pass_their_deviation_unscaled(self):
        x = np.array([[0.1, 0.75, 2.0], [0.3, 0.75, 4.0], [0.2, 0.75, 3.0]], dtype=np.float32)
        norm = rp.Normaliser(x)
        self.assertLess(norm.x_std[1], 2e-6)
        own = norm.constant_in_own_units()
        np.testing.assert_allclose(own.x_std, [norm.x_std[0], 1.0, norm.x_std[2]])
        np.testing.assert_allclose(own(x), norm(x), atol=1e-6)  # the training rows: the same inputs
        off = x[:1] + np.array([[0.0, 0.002, 0.0]], dtype=np.float32)  # the table's height read 2 mm off
        self.assertAlmostEqual(float(own(off)[0, 1]), 0.002, places=5)
        self.assertGreater(float(norm(off)[0, 1]), 1000.0)


if __name__ == "__main__":
    unittest.main()
