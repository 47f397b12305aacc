"""render_bag.py's cut of the capture into the video, without a display: captures made here
the way ffmpeg's x11grab writes them (20 frames/s, wall-clock stamps, frames it skipped under
load missing), each frame's grey level its number.

- video_frames: frames 1/fps apart from the first instant's picture, the last at or after the
  last instant (it shows it) and the one before it before (no frame past the span).
- encode: the video is that many frames, the first at 0 s, each the next captured frame from the
  cut's start on, whatever the cut's phase in the capture's frame grid (a cut a little after a
  captured frame once left the video's first slot empty and its last picture out).
- first_drawn: the stamp of the first changed picture, also where the capture skipped frames
  before it (they once shifted pictures and stamps apart by the frames skipped).
"""
import importlib.util
import os
import subprocess

import numpy as np

from vf_harness import TempDirTestCase, run, script

FPS = 20
SIZE = (64, 48)
CAPTURE_START = 1764100000.0  # wall time of the capture's first frame [s]
GREY_STEP = 4  # grey level per frame number; x264 at crf 23 keeps a flat picture's level to +-1


def render_bag():
    """scripts/render_bag.py as a module (it has no .py package of its own)."""
    spec = importlib.util.spec_from_file_location("render_bag", script("render_bag.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def make_capture(path, seconds, skipped=(), change_at=None):
    """A lossless capture, as start_capture writes it: frame n at CAPTURE_START + n / FPS, grey
    n * GREY_STEP (or, with change_at, black and then white from change_at [s] on), the frames
    numbered in `skipped` left out."""
    grey = f"255*gte(T,{change_at})" if change_at is not None else f"N*{GREY_STEP}"
    keep = "*".join(f"not(eq(n,{n}))" for n in skipped) or "1"
    cmd = ["ffmpeg", "-nostdin", "-v", "error", "-f", "lavfi", "-i",
           f"color=black:s={SIZE[0]}x{SIZE[1]}:r={FPS}:d={seconds},format=gray,geq=lum='{grey}',select='{keep}'",
           "-fps_mode", "passthrough", "-output_ts_offset", str(CAPTURE_START), "-c:v", "libx264rgb", "-preset",
           "ultrafast", "-qp", "0", "-y", path]
    subprocess.run(cmd, check=True, capture_output=True)


def probe(path, entries):
    out = run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries", entries, "-of",
               "default=noprint_wrappers=1", path]).stdout
    return dict(line.split("=", 1) for line in out.split())


def greys(path):
    """The mean grey level of each frame, in order."""
    raw = subprocess.run(["ffmpeg", "-v", "error", "-i", path, "-fps_mode", "passthrough", "-f", "rawvideo",
                          "-pix_fmt", "gray", "-"], check=True, capture_output=True).stdout
    return np.frombuffer(raw, dtype=np.uint8).reshape(-1, SIZE[1] * SIZE[0]).mean(axis=1)


class VideoFramesTest(TempDirTestCase):
    def test_the_frames_reach_the_last_instant_and_no_further(self):
        module = render_bag()
        for seconds in (4.2, 4.2 - 27 * 0.014, 4.2 - 35 * 0.014, 0.05, 1.0, 3.0001):
            for speed, fps in ((2.0, 20), (1.0, 25), (0.5, 60), (4.0, 10)):
                with self.subTest(seconds=seconds, speed=speed, fps=fps):
                    frames = module.video_frames(seconds, speed, fps)
                    # The last frame at or after the last instant, a thousandth of a frame aside.
                    self.assertGreaterEqual((frames - 1) / fps, seconds / speed - 1e-3 / fps)
                    self.assertLess((frames - 2) / fps, seconds / speed)

    def test_an_exact_number_of_frames_is_not_rounded_up(self):
        # 4.2 s at speed 2 is 42 frame intervals at 20 fps, whatever the floating point.
        self.assertEqual(render_bag().video_frames(4.2, 2.0, 20), 43)


class EncodeTest(TempDirTestCase):
    def test_the_cut_whatever_its_phase(self):
        module = render_bag()
        capture = self.path("capture.mkv")
        make_capture(capture, 3.0)
        frames = 12
        # A cut just after a captured frame, half way and just before the next.
        for phase in (0.1, 0.5, 0.9):
            offset = (20 + phase) / FPS  # captured frame 21 is the first from the cut on
            outs = [self.path(f"cut{phase}.mp4"), self.path(f"cut{phase}.gif")]
            module.encode(capture, offset, frames, outs, FPS)
            for out in outs:
                with self.subTest(phase=phase, video=os.path.basename(out)):
                    info = probe(out, "stream=start_time,nb_read_frames,r_frame_rate")
                    self.assertEqual(int(info["nb_read_frames"]), frames)
                    self.assertEqual(info["r_frame_rate"], f"{FPS}/1")
                    self.assertAlmostEqual(float(info["start_time"]), 0.0, delta=1e-3)
                    np.testing.assert_allclose(greys(out), GREY_STEP * np.arange(21, 21 + frames), atol=GREY_STEP / 2)
            self.assertAlmostEqual(float(probe(outs[0], "format=duration")["duration"]), frames / FPS, delta=1e-3)


class FirstDrawnTest(TempDirTestCase):
    def test_the_stamp_of_the_change(self):
        module = render_bag()
        for skipped in ((), (20, 21), (24, 25, 26)):
            with self.subTest(skipped=skipped):
                capture = self.path(f"drawn{len(skipped)}.mkv")
                # The picture changes at 1.5 s; since 1.2 s: the window starts at 0.7 s.
                make_capture(capture, 3.0, skipped=skipped, change_at=1.5)
                start = module.capture_start(capture)
                self.assertAlmostEqual(start, CAPTURE_START, delta=1e-3)
                drawn = module.first_drawn(capture, start, CAPTURE_START + 1.2, *SIZE)
                self.assertAlmostEqual(drawn - CAPTURE_START, 1.5, delta=1e-3)
