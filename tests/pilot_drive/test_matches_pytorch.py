"""autodrive-pilot --predict gives PyTorch's outputs on 20 camera-sized JPEG frames within 1e-4:
the C++ preprocessing (OpenCV: crop, INTER_AREA resize, YUV, scale/mean/std, NCHW) and OpenCV's
DNN run of the exported ONNX model agree with the Python preprocessing and the torch model."""
import pathlib
import subprocess
import tempfile

import cv2
import numpy as np
import torch

import fixture


def test_cpp_pilot_matches_pytorch(root: pathlib.Path, build_dir: pathlib.Path) -> None:
    build = build_dir
    with tempfile.TemporaryDirectory(prefix="pilot-predict-") as tmp:
        out = pathlib.Path(tmp)
        onnx_path, net = fixture.export(out)
        frames = fixture.frames(out, 20)
        r = subprocess.run(
            [str(build / "bin" / "autodrive-pilot"), "--model", str(onnx_path), "--predict"]
            + [str(p) for p in frames],
            capture_output=True, text=True, timeout=60,
        )  # fmt: skip
        assert r.returncode == 0, r.stderr
        cpp = {}
        for line in r.stdout.splitlines():
            path, value = line.rsplit(" ", 1)
            cpp[path] = float(value)
        assert len(cpp) == 20, r.stdout
        worst = 0.0
        outs = []
        with torch.no_grad():
            for p in frames:
                x = fixture.preprocess(cv2.imread(str(p), cv2.IMREAD_COLOR), fixture.INPUT)
                ref = float(net(torch.from_numpy(x))[0, 0])
                outs.append(ref)
                worst = max(worst, abs(ref - cpp[str(p)]))
        print(
            f"20 frames: torch outputs {min(outs):+.4f}..{max(outs):+.4f}, max |C++ - torch| = {worst:.2e}"
        )
        assert (
            np.std(outs) > 1e-3
        ), "the frames must give different outputs for the test to mean anything"
        assert worst <= 1e-4, f"C++ and PyTorch differ by {worst}"
    print("OK")
