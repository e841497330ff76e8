"""Opens a run's .xdmf in ParaView as a user would, with no workaround (docs/guide/results.md,
docs/reference/output.md): with the XDMF Reader, Xdmf3ReaderS and Xdmf3ReaderT, by a relative
name from another working directory; checks every step has a time, the point vectors have 3
components and the stress is named scalars; applies Warp By Vector on `displacement` and saves a
screenshot (under Xvfb when there is no display).
Run with Debian's ParaView python (scripts/install-deps --paraview):
  xvfb-run -a -s "-screen 0 1280x1024x24" pvpython tests/python/paraview_open.py --bin build/voussoir --work DIR \
      [--picture F.png] [--deck D.toml] [--set KEY=VALUE ...] [--scale S]
(ctest: paraview_open, label slow). Without --deck: the shipped block sliding for 0.05 s."""
import argparse
import os
import subprocess


from checks import SOURCE, check, finish


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--picture", default="")
    ap.add_argument("--deck", default=os.path.join(SOURCE, "cases", "block.toml"))
    ap.add_argument("--set", action="append", default=None)
    ap.add_argument("--scale", type=float, default=1.0, help="Warp By Vector scale factor")
    a = ap.parse_args()
    work = os.path.abspath(a.work)
    picture = os.path.abspath(a.picture) if a.picture else ""  # before the chdir below
    os.makedirs(os.path.join(work, "elsewhere"), exist_ok=True)
    sets = a.set if a.set is not None else ["load.lambda=0.3", "contact.friction=0.2",
                                            "solver.end_time=0.05", "output.every=0.01"]
    h5 = os.path.join(work, "out", "run.h5")
    cmd = [os.path.abspath(a.bin), "run", os.path.abspath(a.deck), "-o", h5, "-q"]
    for s in sets:
        cmd += ["--set", s]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    # ParaView after the run: a long run between importing paraview.simple (which opens the X
    # display) and the first render broke the GLX context under Xvfb (GLXBadContext).
    from paraview.simple import (ColorBy, CreateView, Hide, SaveScreenshot, Show, WarpByVector,
                                 XDMFReader, Xdmf3ReaderS, Xdmf3ReaderT)
    # Opened by a relative name from another folder: the .h5 must resolve against the .xdmf's.
    os.chdir(os.path.join(work, "elsewhere"))
    xdmf = os.path.join("..", "out", "run.xdmf")
    with open(xdmf) as f:
        with_stress = "stress_xx" in f.read()  # not for rigid blocks

    readers = {"XDMFReader": XDMFReader(FileNames=[xdmf]),
               "Xdmf3ReaderS": Xdmf3ReaderS(FileName=[xdmf]),
               "Xdmf3ReaderT": Xdmf3ReaderT(FileName=[xdmf])}
    view = CreateView("RenderView")
    view.ViewSize = [1200, 700]
    view.OrientationAxesVisibility = 0
    for name, r in readers.items():
        r.UpdatePipelineInformation()
        times = list(r.TimestepValues) if r.TimestepValues else []
        check(len(times) >= 2, f"{name}: time steps {times}")
        t_end = times[-1] if times else 0.0
        r.UpdatePipeline(t_end)
        pd, cd = r.PointData, r.CellData
        for vec in ("displacement", "velocity"):
            arr = pd.GetArray(vec)
            check(arr is not None, f"{name}: point array {vec}")
            if arr is not None:
                check(arr.GetNumberOfComponents() == 3, f"{name}: {vec} has 3 components")
        for s in ("stress_xx", "stress_yy", "stress_xy", "stress_1", "stress_2"):
            arr = cd.GetArray(s)
            if with_stress:
                check(arr is not None and arr.GetNumberOfComponents() == 1,
                      f"{name}: cell scalar {s}")
            else:
                check(arr is None, f"{name}: no {s} (rigid blocks have no stress field)")
        disp = pd.GetArray("displacement")
        umax = max(abs(disp.GetRange(0)[0]), abs(disp.GetRange(0)[1])) if disp else 0.0
        check(umax > 0.0, f"{name}: the structure moved at t = {t_end}")
        warp = WarpByVector(Input=r)
        warp.Vectors = ["POINTS", "displacement"]
        warp.ScaleFactor = a.scale
        warp.UpdatePipeline(t_end)
        # The warped points are the reference points moved by scale x displacement.
        bounds_ref = r.GetDataInformation().GetBounds()
        bounds = warp.GetDataInformation().GetBounds()
        check(bounds != bounds_ref, f"{name}: Warp By Vector moved the mesh")
        print(f"{name}: {len(times)} steps, t = {times[0] if times else None}..{t_end} s, "
              f"max |ux| {umax:.4g} m, bounds {tuple(round(b, 4) for b in bounds[:4])}")
        view.ViewTime = t_end
        shown = Show(warp, view)
        ColorBy(shown, ("POINTS", "displacement", "Magnitude"))
        shown.SetScalarBarVisibility(view, True)
        ref = Show(r, view)
        ref.Representation = "Wireframe"
        ref.AmbientColor = ref.DiffuseColor = [0.6, 0.6, 0.6]
        ColorBy(ref, None)
        view.ResetCamera()
        view.CameraPosition = [view.CameraFocalPoint[0], view.CameraFocalPoint[1],
                               view.CameraFocalPoint[2] + 10.0]
        view.CameraViewUp = [0, 1, 0]
        view.ResetCamera()
        png = picture if (picture and name == "Xdmf3ReaderS") else os.path.join(
            work, f"{name}.png")
        SaveScreenshot(png, view, ImageResolution=[1200, 700])
        check(os.path.getsize(png) > 1000, f"{name}: screenshot {png}")
        Hide(warp, view)
        Hide(r, view)
    finish("paraview_open")


if __name__ == "__main__":
    main()
