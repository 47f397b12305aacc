"""Unit tests of the pure helpers of the Python package (src/variational_formation): the file
readers (data), the one-line failure (cli) and the Noether prediction and summary (plots)."""
import math
import os
import subprocess
import textwrap

import numpy as np

from vf_harness import PYTHON, REPO, TempDirTestCase
from variational_formation import data, plots


class DataTest(TempDirTestCase):
    def write(self, name, text):
        path = self.path(name)
        with open(path, "w") as f:
            f.write(textwrap.dedent(text))
        return path

    def test_trajectory_layout_is_step_agent_axis(self):
        path = self.write("t.csv", """\
            step,t,agent,x,y,z
            0,0,0,1,2,3
            0,0,1,4,5,6
            1,0.1,0,7,8,9
            1,0.1,1,10,11,12
            """)
        q = data.read_trajectory(path)
        self.assertEqual(q.shape, (2, 2, 3))
        np.testing.assert_array_equal(q[1, 0], [7, 8, 9])
        np.testing.assert_array_equal(q[0, 1], [4, 5, 6])

    def test_metrics_columns(self):
        path = self.write("m.csv", """\
            step,t,energy,max_distance_error,px,py,pz,ax,ay,az
            0,0,2.5,0.3,1,2,3,4,5,6
            1,0.5,1.5,0.2,7,8,9,10,11,12
            """)
        m = data.read_metrics(path)
        np.testing.assert_array_equal(m.t, [0, 0.5])
        np.testing.assert_array_equal(m.energy, [2.5, 1.5])
        np.testing.assert_array_equal(m.error, [0.3, 0.2])
        np.testing.assert_array_equal(m.p[1], [7, 8, 9])
        np.testing.assert_array_equal(m.a[0], [4, 5, 6])
        self.assertTrue(np.all(np.isnan(m.cv)) and np.all(np.isnan(m.scale_error)))  # written before tracking

    def test_metrics_tracking_columns(self):
        path = self.write("m.csv", """\
            step,t,energy,max_distance_error,px,py,pz,ax,ay,az,cvx,cvy,cvz,wx,wy,wz,scale_error
            0,0,2.5,0.3,1,2,3,4,5,6,0.1,0.2,0,0,0,0.5,0.01
            1,0.5,1.5,0.2,7,8,9,10,11,12,0.3,0.4,0,0,0,0.6,0.02
            """)
        m = data.read_metrics(path)
        np.testing.assert_array_equal(m.a[1], [10, 11, 12])
        np.testing.assert_array_equal(m.cv[1], [0.3, 0.4, 0])
        np.testing.assert_array_equal(m.w[0], [0, 0, 0.5])
        np.testing.assert_array_equal(m.scale_error, [0.01, 0.02])

    def test_scenario_fields(self):
        s = data.read_scenario(os.path.join(REPO, "config", "hexagon.yaml"))
        self.assertEqual((s.name, s.dimension, s.n), ("hexagon", 2, 6))
        self.assertEqual((s.kappa, s.time_step), (13.0, 0.014))
        self.assertEqual(s.desired.shape, (6, 2))
        self.assertIn((0, 3), s.edges)

    def helper_fails(self, code):
        """Runs `code` (using the package) in a child: its exit status and stderr."""
        env = dict(os.environ, PYTHONPATH=os.path.join(REPO, "src"))
        child = subprocess.run([PYTHON, "-c", code], capture_output=True, text=True, env=env, cwd=self.tmp)
        return child.returncode, child.stderr.strip().splitlines()

    def test_wrong_header_is_one_line_and_exit_2(self):
        path = self.write("bad.csv", "a,b\n1,2\n")
        status, lines = self.helper_fails(f"from variational_formation import data; data.read_metrics({path!r})")
        self.assertEqual(status, 2)
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("expected header", lines[0])

    def test_rows_not_a_multiple_of_the_agents_fail(self):
        path = self.write("t.csv", "step,t,agent,x,y,z\n0,0,0,1,2,3\n0,0,1,4,5,6\n1,0.1,0,7,8,9\n")
        status, lines = self.helper_fails(f"from variational_formation import data; data.read_trajectory({path!r}, 2)")
        self.assertEqual(status, 2)
        self.assertIn("rows are not agents 0..1 step after step", lines[-1])

    def test_missing_scenario_field_fails(self):
        path = self.write("s.yaml", "name: x\ndimension: 2\n")
        status, lines = self.helper_fails(f"from variational_formation import data; data.read_scenario({path!r})")
        self.assertEqual(status, 2)
        self.assertIn("cannot read the scenario", lines[-1])

    def test_fail_names_the_script_on_one_line(self):
        status, lines = self.helper_fails("import sys; sys.argv = ['/x/my_tool.py']\n"
                                          "from variational_formation.cli import fail\nfail('bad\\n  value')")
        self.assertEqual((status, lines), (2, ["my_tool: error: bad value"]))


class PlotsTest(TempDirTestCase):
    def test_noether_prediction_is_powers_of_the_step_factor(self):
        kappa, h = 2.0, 0.01
        initial = np.array([1.0, -2.0, 0.5])
        steps = np.arange(5, dtype=float)
        predicted = plots.noether_prediction(initial, kappa, h, steps)
        for k in range(5):
            np.testing.assert_allclose(predicted[k], math.exp(-kappa * h) ** k * initial, rtol=1e-15)

    def test_momentum_residuals_vanish_on_the_exact_law(self):
        kappa, h, steps = 3.0, 0.02, 50
        factor = np.power(math.exp(-kappa * h), np.arange(steps))[:, None]
        p = factor * np.array([1.0, 2.0, 0.0])
        a = factor * np.array([0.0, 0.0, -4.0])
        res_p, res_a = plots.momentum_residuals(p, a, kappa, h)
        self.assertLess(res_p.max(), 1e-14)
        self.assertLess(res_a.max(), 1e-14)
        # A momentum off the law by 1e-3 at one step shows exactly there.
        p[10, 0] += 1e-3
        res_p, _ = plots.momentum_residuals(p, a, kappa, h)
        self.assertAlmostEqual(res_p[10], 1e-3, delta=1e-12)
        self.assertEqual(int(np.argmax(res_p)), 10)

    def test_summary_reports_the_figures(self):
        t = np.array([0.0, 0.5, 1.0])
        energy = np.array([4.0, 2.0, 1.0])
        error = np.array([0.5, 0.1, 0.02])
        zeros = np.zeros((3, 3))
        text = plots.summary(t, energy, error, zeros, zeros, 1.0, 0.5)
        self.assertIn("steps: 2, final time 1.000 s", text)
        self.assertIn("2.000e-02 m", text)
        self.assertIn("E_final / E_0: 2.500e-01", text)

    def test_plot_all_writes_four_pngs(self):
        steps = 20
        t = np.linspace(0, 1, steps)
        q = np.random.default_rng(1).normal(size=(steps, 3, 3))
        q[:, :, 2] = 0
        series = np.linspace(1, 0.1, steps)
        p = np.ones((steps, 3))
        paths = plots.plot_all(self.tmp, "x", "x", t, q, 2, series, series, p, p, 1.0, 0.05, [(0, 1)])
        self.assertEqual(sorted(paths), ["energy", "error", "momenta", "trajectories"])
        for path in paths.values():
            self.assertPng(path)
