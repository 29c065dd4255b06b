"""Library modules draw without choosing matplotlib's backend: only command-line tools may."""
import os
import subprocess
import sys


def test_importing_plotting_modules_keeps_the_callers_backend():
    code = ("import matplotlib; import constitutive.fit.plots, drape.analyses.drape_coefficient, drape.run.pictures, "
            "drape.batch.prediction; "
            "print(matplotlib.get_backend())")
    env = {**os.environ, "MPLBACKEND": "pdf"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True, cwd=os.path.dirname(os.path.dirname(__file__)))
    assert out.stdout.strip() == "pdf"
