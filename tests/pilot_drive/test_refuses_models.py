"""autodrive-pilot refuses, naming the file, a model it cannot run: a truncated .onnx, a missing
one, an opset outside 11..13, and a sidecar whose input shape the network cannot take."""
import json
import pathlib
import subprocess
import tempfile

import fixture


def test_refuses_bad_models(root: pathlib.Path, build_dir: pathlib.Path) -> None:
    build = build_dir
    pilot = str(build / "bin" / "autodrive-pilot")

    def refused(model: pathlib.Path, *words: str) -> None:
        r = subprocess.run(
            [pilot, "--model", str(model), "--check"], capture_output=True, text=True, timeout=60
        )
        print(f"{model.name}: exit {r.returncode}: {r.stderr.strip()}")
        assert r.returncode == 2, r
        for w in words:
            assert w in r.stderr, f"'{w}' not in: {r.stderr}"

    with tempfile.TemporaryDirectory(prefix="pilot-refuse-") as tmp:
        out = pathlib.Path(tmp)
        good, _ = fixture.export(out, "good")
        r = subprocess.run(
            [pilot, "--model", str(good), "--check"], capture_output=True, text=True, timeout=60
        )
        assert r.returncode == 0, r.stderr
        # truncated: the same bytes cut in half, the sidecar as exported
        cut = out / "cut.onnx"
        data = good.read_bytes()
        cut.write_bytes(data[: len(data) // 2])
        (out / "cut.json").write_text(good.with_suffix(".json").read_text())
        refused(cut, str(cut), "truncated")
        # truncated with a sidecar that matches the cut bytes: the ONNX structure gives it away
        side = json.loads((out / "cut.json").read_text())
        import hashlib

        side["onnx_sha256"] = hashlib.sha256(cut.read_bytes()).hexdigest()
        (out / "cut.json").write_text(json.dumps(side))
        refused(cut, str(cut))
        refused(out / "missing.onnx", str(out / "missing.onnx"), "cannot be opened")
        old, _ = fixture.export(out, "old", opset=9)
        refused(old, str(old), "opset 9")
        shape = dict(fixture.INPUT, height=80)
        wrong, _ = fixture.export(out, "wrong", spec=shape)
        refused(wrong, str(wrong), "input shape [1,3,80,200]")
    print("OK")
