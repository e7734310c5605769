"""rtoracle's driver of a course submission's own program (render requests with "program").

The course adapter (course_adapter.py) loads this file, written beside it, on the first render
request that names a "program": one of the submission's main.py render functions
(renderMoving, renderBlinn, ...). The function is run unmodified, once per (function, size,
spp, depth, seed), so that the image is made by the submission's own scene, camera, renderer and
film. Only what main.py cannot be asked for is changed, for the call alone:

- Camera.init_camera sets img_width, samples_per_pixel and max_depth to the request's before it
  runs (main.py's aspect ratio, camera, lens, scene and render method are kept);
- PIL's Image.save keeps the picture the function saves instead of writing a file (the film
  codes are exactly what the student's program would write to its PNG);
- numpy's global RNG, random's, and every np.random.default_rng() made without a seed are seeded
  from the request's seed (the course seeds nothing), so that the same request gives the same
  codes;
- RT_pbar (progressbar2) is replaced by a silent stand-in before main.py is imported;
- a request with a "variant" (a scene the grader moved, so that no picture made in advance can
  show it) moves the camera in Camera.init_camera: "look_from" and "look_at" are added to
  main.py's look_from and look_at, and its vertical_fov is multiplied by "vfov_scale", once per
  camera whatever the number of init_camera calls;
- PIL's Image.open reads the grader's own pictures in place of the files main.py names: a file
  whose name without its folder and extension is a picture of the request's scene (an image
  texture's "name", or "earthmap" for "earth") is opened from the picture the request carries,
  so that the submission's ImageTexture reads exactly the texels the reference reads, whatever
  pictures (or none) the submission's folder holds.

A function that does not exist, saves no picture, or saves one of another size than the
request's is *declined* (the grader then renders its own description of the scene with the
submission's classes and says why). A function that raises is the submission's error.
"""

import importlib
import sys
import types


class Declined(Exception):
    """The program cannot render what was asked: why, for the report."""


class _SilentBar:
    def update(self, k):
        pass

    def finish(self):
        pass

    def start(self):
        return self


def _silent_pbar():
    pbar = types.ModuleType("RT_pbar")
    pbar.start_animated_marker = lambda *args, **kwargs: _SilentBar()
    return pbar


def _seeded(seed):
    """Seeds the RNGs the course draws from; returns what undoes the default_rng patch."""
    import random
    random.seed(seed)
    np = sys.modules.get("numpy")
    if np is None:
        try:
            import numpy as np
        except ImportError:
            return lambda: None
    np.random.seed(seed % (1 << 32))
    made = np.random.default_rng
    count = [0]

    def default_rng(*args, **kwargs):
        if not args and not kwargs:
            count[0] += 1
            return made((seed + count[0]) % (1 << 32))
        return made(*args, **kwargs)

    np.random.default_rng = default_rng

    def undo():
        np.random.default_rng = made
    return undo


# File names main.py gives its pictures that are not the scene's texture names.
PICTURE_ALIASES = {"earthmap": "earth"}


def _pictures(scene):
    """The scene's pictures by texture name: the PNG bytes the request carries."""
    out = {}
    for t in scene.get("textures", []) or []:
        data = t.get("png_hex") if isinstance(t, dict) else None
        if isinstance(data, str) and isinstance(t.get("name"), str):
            out[t["name"]] = bytes.fromhex(data)
    return out


def _picture_for(path, pictures):
    """The picture the grader brings for the file `path` main.py opens, or None."""
    import os
    try:
        stem = os.path.splitext(os.path.basename(os.fspath(path)))[0]
    except TypeError:
        return None
    name = PICTURE_ALIASES.get(stem.lower(), stem)
    return pictures.get(name)


def _moved(camera, variant, Vec3):
    """Moves `camera` by the request's variant once (main.py may call init_camera again)."""
    if not variant:
        return
    mark = getattr(camera, "_rtoracle_variant", None)
    if mark is not None and mark[0] is camera.look_from and mark[1] is camera.look_at \
            and mark[2] == camera.vertical_fov:
        return
    d_from, d_at = variant.get("look_from", [0, 0, 0]), variant.get("look_at", [0, 0, 0])
    camera.look_from = camera.look_from + Vec3(float(d_from[0]), float(d_from[1]), float(d_from[2]))
    camera.look_at = camera.look_at + Vec3(float(d_at[0]), float(d_at[1]), float(d_at[2]))
    camera.vertical_fov = camera.vertical_fov * float(variant.get("vfov_scale", 1.0))
    camera._rtoracle_variant = (camera.look_from, camera.look_at, camera.vertical_fov)


def _patched(obj, name, value, undo):
    undo.append((obj, name, getattr(obj, name)))
    setattr(obj, name, value)


def run(req):
    """Runs the request's program; returns (width, height, codes) with codes a bytes object of
    3 codes per pixel, row-major, top row first. Raises Declined, or what the program raises."""
    name = req["program"]
    if not isinstance(name, str) or not name.isidentifier():
        raise Declined("%r is not a function name" % (name,))
    image = req["scene"]["image"]
    width, spp = int(image["width"]), int(req["spp"])
    depth = int(req["scene"].get("render", {}).get("max_depth", 0) or 0)
    if "RT_pbar" not in sys.modules or not hasattr(sys.modules["RT_pbar"], "start_animated_marker"):
        sys.modules["RT_pbar"] = _silent_pbar()
    try:
        main = sys.modules.get("main") or importlib.import_module("main")
    except ModuleNotFoundError as e:
        if e.name == "main":
            raise Declined("the submission has no main.py")
        raise
    function = getattr(main, name, None)
    if not callable(function):
        raise Declined("main.py has no function %s" % (name,))
    RT_camera = sys.modules.get("RT_camera") or importlib.import_module("RT_camera")
    Camera = getattr(RT_camera, "Camera", None)
    if Camera is None or not callable(getattr(Camera, "init_camera", None)):
        raise Declined("RT_camera.py has no Camera.init_camera")
    from PIL import Image
    import io

    variant = req.get("variant")
    Vec3 = None
    if variant:
        RT_utility = sys.modules.get("RT_utility") or importlib.import_module("RT_utility")
        Vec3 = getattr(RT_utility, "Vec3", None)
        if Vec3 is None:
            raise Declined("RT_utility.py has no Vec3, which moving the camera needs")
    pictures = _pictures(req["scene"])
    saved = []
    undo = []
    init_camera = Camera.init_camera
    open_image = Image.open

    def sized_init_camera(self, *a, **k):
        self.img_width = width
        self.samples_per_pixel = spp
        if depth > 0:
            self.max_depth = depth
        _moved(self, variant, Vec3)
        return init_camera(self, *a, **k)

    def keep(self, *a, **k):
        saved.append(self.convert("RGB"))

    def grader_picture(fp, *a, **k):
        data = _picture_for(fp, pictures) if isinstance(fp, (str, bytes)) or hasattr(fp, "__fspath__") else None
        if data is not None:
            return open_image(io.BytesIO(data))
        return open_image(fp, *a, **k)

    _patched(Camera, "init_camera", sized_init_camera, undo)
    _patched(Image.Image, "save", keep, undo)
    _patched(Image, "open", grader_picture, undo)
    unseed = _seeded(int(req.get("seed", 0)))
    try:
        function()
    finally:
        unseed()
        for obj, attr, value in reversed(undo):
            setattr(obj, attr, value)
    if not saved:
        raise Declined("main.py's %s saved no picture through PIL" % (name,))
    picture = saved[-1]
    return picture.size[0], picture.size[1], picture.tobytes()


class ProgramRenderer:
    """Answers the tiles of program render requests from one run of the program."""

    def __init__(self):
        self.key = None
        self.made = None

    def answer(self, req, key):
        """The tile's answer as JSON text; raises Declined or what the program raises."""
        if key != self.key:
            self.key, self.made = None, None
            self.made = run(req)
            self.key = key
        width, height, codes = self.made
        x0, y0, x1, y1 = (int(v) for v in req["tile"])
        if not (0 <= x0 < x1 <= width and 0 <= y0 < y1 <= height):
            raise Declined("main.py's %s made a %dx%d image, without the tile %r"
                           % (req["program"], width, height, req["tile"]))
        parts = []
        for j in range(y0, y1):
            row = codes[3 * (j * width + x0):3 * (j * width + x1)]
            parts.append(",".join(str(c) for c in row))
        return '{"tile":[%d,%d,%d,%d],"size":[%d,%d],"film":[%s]}' % (
            x0, y0, x1, y1, width, height, ",".join(parts))
