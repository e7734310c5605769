"""rtoracle's adapter for the course's Python API (protocol 1, JSON lines, stdlib only).

Usage: python3 -I -B python_course.py SUBMISSION_DIR [--name NAME] [--prints-to-stderr]
                                        [--requires numpy,PIL]

Imports RT_utility, RT_ray and RT_object from SUBMISSION_DIR (rtoracle runs it in its sandbox
folder, where the submission's .py files are copied, with SUBMISSION_DIR "."), builds the course's objects with
their constructors and answers one request line with one answer line, in order. Answers are
written in batches (see _Channel), or one by one when a request says "sync": true (the harness
asks for that after a crash or timeout, since a crash loses the answers not yet written).

It drives every week's API unmodified: a `Ray` with extra defaulted parameters (`fTime=0.0`), a
`Triangle` whose constructor takes a material (`Triangle(v0, v1, v2, mat)`, given `None`) or
none, answers holding numpy floats or arrays (read with float() and bool()). A module the
submission imports that is neither its own nor in `--requires` (default numpy and PIL) is
reported as the student's ("your code imports scipy (RT_extra.py, line 3), which the grader
does not provide"); a missing required module is said to be the grader's. An error raised inside
multiprocessing (no semaphores without /dev/shm, no worker past the sandbox's process bound) says
what is missing and what to do.

The requests for the course's functions of weeks 5 to 10 (reflect, refract, the samplers, ...;
docs/PROTOCOL.md, "Function requests") are answered by rtoracle's driver, a second file written
beside this one (FUNCTIONS_FILE); the hello lists them in "ops" when it is there.

A "render" request (docs/PROTOCOL.md, "Render requests") renders one tile of a scene with the
submission's own classes: RT_scene.Scene, RT_object.Sphere / Quad / Triangle, RT_material's
materials, RT_camera.Camera and RT_integrator.Integrator, looping over the pixels here (so the
course's RT_renderer and its progress bar are never imported). The answer is the tile's mean
linear RGB, or {"declined": why} for a scene the submission's classes cannot build. A render
request naming a "program" (a main.py render function) is answered by a third file written
beside this one (PROGRAM_FILE): the function is run unmodified and the answer is the 8-bit film
it saves, as "film" codes.
"""

import importlib.util
import inspect
import json
import os
import sys
import threading
import time
import traceback

INF = float("inf")
TB_LIMIT = 4000


def num(x):
    """A float in the protocol's syntax (non-finite numbers as strings)."""
    x = float(x)
    if x != x:
        return '"nan"'
    if x == INF:
        return '"inf"'
    if x == -INF:
        return '"-inf"'
    return repr(x)


def vec(v):
    # A Vec3 (components in .e, a list or a numpy array), or a bare sequence or array.
    e = getattr(v, "e", v)
    return "[" + num(e[0]) + "," + num(e[1]) + "," + num(e[2]) + "]"


def truth(x):
    """front_face as a JSON boolean: Python and numpy booleans (np.bool_), 0 and 1."""
    if x is True or x is False:
        return "true" if x else "false"
    return "true" if bool(x) else "false"


REQUIRES = ["numpy", "PIL"]
SUBMISSION = "."
# rtoracle's driver of the course's functions, written beside this file.
FUNCTIONS_FILE = "rtoracle_course_functions.py"
# rtoracle's driver of the submission's own main.py (render requests naming a "program").
PROGRAM_FILE = "rtoracle_course_program.py"


def load_functions():
    """The functions driver (a module with OPS and answer(request)), or None without it."""
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), FUNCTIONS_FILE)
    if not os.path.isfile(path):
        return None
    spec = importlib.util.spec_from_file_location("rtoracle_course_functions", path)
    driver = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(driver)
    driver.set_submission(SUBMISSION)
    return driver


def where_raised(exc):
    """"FILE, line N" of the deepest frame of exc's traceback in the submission's folder, or
    None."""
    folder = os.path.abspath(SUBMISSION)
    own = os.path.abspath(__file__)
    where = None
    for frame in traceback.extract_tb(exc.__traceback__):
        path = os.path.abspath(frame.filename)
        name = os.path.basename(path)
        # The adapter and rtoracle's drivers sit beside the submission's files: not its code.
        if path == own or name.startswith("rtoracle_"):
            continue
        if os.path.dirname(path) == folder:
            where = "%s, line %d" % (name, frame.lineno)
    return where


def missing_module_message(exc):
    """What a ModuleNotFoundError means for grading, or None to keep Python's message."""
    name = getattr(exc, "name", None)
    if not isinstance(name, str) or not name:
        return None
    top = name.split(".")[0]
    where = where_raised(exc)
    if where is not None and top not in REQUIRES:
        top_in = "%s (%s)" % (top, where)
    else:
        top_in = top
    if top in REQUIRES:
        return (
            "the grader's Python lacks %s, which the assignment requires: this is the "
            "grader's problem, not the submission's (tell the instructor)" % top
        )
    own = os.path.join(SUBMISSION, top + ".py")
    if top.startswith("RT_") and not os.path.exists(own):
        return (
            "your code imports %s, which is not in your submission folder (add %s.py to it)"
            % (top_in, top)
        )
    return "your code imports %s, which the grader does not provide" % top_in


def multiprocessing_message(exc):
    """What an error raised inside multiprocessing means in the grader's sandbox, with what to
    do, or None when it is not one."""
    import errno
    frames = traceback.extract_tb(exc.__traceback__)
    if not any(os.sep + "multiprocessing" + os.sep in f.filename for f in frames):
        return None
    if not isinstance(exc, OSError):
        return None
    if exc.errno in (errno.EAGAIN, errno.ENOMEM, errno.EMFILE, errno.ENFILE):
        return (
            "multiprocessing could not start its worker processes (%s): the grader's sandbox "
            "bounds the processes, open files and memory of your code; ask for a few workers "
            "(multiprocessing.Pool(4), not one per CPU of the grader's machine) or render in one "
            "process when the pool cannot start" % exc
        )
    if exc.errno in (errno.EROFS, errno.ENOENT, errno.EACCES, errno.ENOSYS, errno.ENOSPC):
        return (
            "multiprocessing could not make its locks and semaphores (%s): they live in "
            "/dev/shm, which this sandbox does not give (or is full); render in one process "
            "when the pool cannot start (try: pool = multiprocessing.Pool(n) / "
            "except OSError: render without it)" % exc
        )
    return None


# The adapter's own files, written beside the submission's modules: never the student's frame.
ADAPTER_FILES = ("course_adapter.py", FUNCTIONS_FILE, PROGRAM_FILE)
# Longest file name, function name and line of code an error's place keeps.
PLACE_LIMIT = 200


def raised_in(exc):
    """Where the submission's own code raised exc: (file, line, function, code) of the last
    frame in the submission's folder that is not one of the adapter's files (for a SyntaxError,
    the file and line Python could not compile), or None when no frame is the submission's."""
    folder = os.path.abspath(SUBMISSION)

    def own(path):
        path = os.path.abspath(path or "")
        name = os.path.basename(path)
        return os.path.dirname(path) == folder and name.endswith(".py") and name not in ADAPTER_FILES

    place = None
    try:
        for frame in traceback.extract_tb(exc.__traceback__):
            if own(frame.filename):
                place = (frame.filename, frame.lineno, frame.name, frame.line)
        if isinstance(exc, SyntaxError) and own(exc.filename) and exc.lineno:
            place = (exc.filename, exc.lineno, None, exc.text)
    except Exception:
        return None
    if place is None or not isinstance(place[1], int):
        return None
    path, line, function, code = place
    code = (code or "").strip()
    return {
        "file": os.path.basename(path)[:PLACE_LIMIT],
        "line": line,
        "function": function[:PLACE_LIMIT] if isinstance(function, str) else None,
        "code": code[:PLACE_LIMIT] if code else None,
    }


def error_json(exc):
    """The protocol's error object of exc: its type, message and traceback (from the first
    frame past the adapter's), and where the submission raised it ("file", "line", "function",
    "code": raised_in), so that every report can name the student's file and line."""
    # Leave out the adapter's own frame: the traceback starts in the submission.
    raw = exc.__traceback__
    raw = raw.tb_next if raw else None
    tb = "".join(traceback.format_exception(type(exc), exc, raw))
    if len(tb) > TB_LIMIT:
        tb = "..." + tb[-TB_LIMIT:]
    place = raised_in(exc)
    message = None
    if isinstance(exc, ModuleNotFoundError):
        try:
            message = missing_module_message(exc)
        except Exception:
            message = None
        if message is not None:
            # The traceback ends with what the grader means, not Python's "No module named".
            frames = traceback.format_tb(raw)
            tb = "Traceback (most recent call last):\n" + "".join(frames)
            tb += "ModuleNotFoundError: " + message + "\n"
            if len(tb) > TB_LIMIT:
                tb = "..." + tb[-TB_LIMIT:]
    if message is None and isinstance(exc, SyntaxError) and place is not None:
        # Python's message ends with "(RT_object.py, line 19)": the place says it.
        message = exc.msg if isinstance(exc.msg, str) else None
    if message is None:
        try:
            message = multiprocessing_message(exc)
        except Exception:
            message = None
    if message is None:
        try:
            message = str(exc)
        except Exception:
            message = "(the exception's message cannot be printed)"
    error = {"type": type(exc).__name__, "message": message[:TB_LIMIT], "traceback": tb}
    if place is not None:
        for key, value in place.items():
            if value is not None:
                error[key] = value
    return json.dumps(error)


def triangle_maker(Triangle, Vec3):
    """A function (a, b, c) -> a Triangle, or None when the class cannot make one.

    The constructor's signature says how: three vertices, plus None for each further required
    parameter (a material). The week-4 stub (no vertices) and a class whose objects have no
    callable intersect are unsupported.
    """
    if Triangle is None:
        return None
    extra = 0
    try:
        params = list(inspect.signature(Triangle).parameters.values())
    except (TypeError, ValueError):
        params = None
    if params is not None:
        positional = [
            p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)
        ]
        varargs = any(p.kind == p.VAR_POSITIONAL for p in params)
        required = [p for p in positional if p.default is p.empty]
        if len(positional) < 3 and not varargs:
            return None
        extra = max(0, len(required) - 3)
        if any(p.kind == p.KEYWORD_ONLY and p.default is p.empty for p in params):
            return None
    nones = (None,) * extra

    def make(a, b, c):
        return Triangle(a, b, c, *nones)

    try:
        t = make(Vec3(0.0, 0.0, 0.0), Vec3(1.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0))
        if not callable(getattr(t, "intersect", None)):
            return None
    except BaseException:
        return None
    return make


# --- render requests ------------------------------------------------------------------------

# A scene's materials as the course's classes of weeks 4 to 10 take them: the class name in
# RT_material and the entry's keys after the colour (CookTorrance takes the colour in week 8 only,
# so its arguments follow its signature).
MATERIAL_CLASSES = {
    "lambertian": ("Lambertian", ()),
    "diffuse_light": ("Diffuse_light", ()),
    "mirror": ("Mirror", ()),
    "dielectric": ("Dielectric", ("ior",)),
    "metal": ("Metal", ("roughness",)),
    "phong": ("Phong", ("kd", "ks", "alpha")),
    "blinn": ("Blinn", ("kd", "ks", "alpha")),
    "cook_torrance": ("CookTorrance", ("kd", "ks", "alpha", "ior")),
    "textured": ("TextureColor", ()),
}


# The material classes the course defines in RT_light.py (week 5 on), not RT_material.py.
LIGHT_CLASSES = ("Diffuse_light",)


class Declined(Exception):
    """The submission's classes cannot build this scene (the answer says why)."""


def positional_count(f):
    try:
        params = inspect.signature(f).parameters.values()
    except (TypeError, ValueError):
        return None
    return len([p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)])


class SceneBuilder:
    """Builds a scene description (the request's "scene") from the submission's classes."""

    def __init__(self, Vec3, make_triangle):
        import RT_utility
        self.rtu = RT_utility
        self.Vec3 = Vec3
        self.make_triangle = make_triangle
        self.modules = {}

    def module(self, name):
        if name not in self.modules:
            if name not in sys.modules and not os.path.exists(os.path.join(SUBMISSION, name + ".py")):
                raise Declined("the submission has no %s.py, which rendering needs" % name)
            self.modules[name] = __import__(name)
        return self.modules[name]

    def cls(self, module, name):
        c = getattr(self.module(module), name, None)
        if c is None:
            raise Declined("%s.py has no class %s, which the scene needs" % (module, name))
        return c

    def material_class(self, name):
        """A material class: from RT_light.py where the course keeps its lights (Diffuse_light,
        from week 5 on), else from RT_material.py."""
        if name in LIGHT_CLASSES and os.path.exists(os.path.join(SUBMISSION, "RT_light.py")):
            c = getattr(self.module("RT_light"), name, None)
            if c is not None:
                return c
        return self.cls("RT_material", name)

    def color(self, c):
        return self.rtu.Color(float(c[0]), float(c[1]), float(c[2]))

    def v3(self, a):
        return self.Vec3(float(a[0]), float(a[1]), float(a[2]))

    def texture(self, t):
        kind = t.get("type")
        if kind == "solid":
            return self.cls("RT_texture", "SolidColor")(self.color(t["color"]))
        if kind == "checker":
            make = self.cls("RT_texture", "CheckerTexture")
            return make(float(t["scale"]), self.color(t["even"]), self.color(t["odd"]))
        if kind == "image":
            # The grader sends the picture itself (a PNG, as hex): the submission's
            # ImageTexture reads it from a file of the sandbox's own /tmp.
            data = t.get("png_hex")
            if not isinstance(data, str):
                raise Declined("the image texture %r came without its picture" % (t.get("name"),))
            return self.cls("RT_texture", "ImageTexture")(self.picture_file(bytes.fromhex(data)))
        raise Declined("the adapter cannot build %r textures" % (kind,))

    def picture_file(self, data):
        """A file holding `data` (a PNG) in a private folder, named as the course names pictures."""
        import tempfile
        if getattr(self, "pictures", None) is None:
            self.pictures = tempfile.mkdtemp(prefix="rtoracle-pictures-")
        path = os.path.join(self.pictures, "picture-%d.png" % len(os.listdir(self.pictures)))
        with open(path, "wb") as f:
            f.write(data)
        return path

    def material(self, m, textures):
        kind = m.get("type")
        if kind not in MATERIAL_CLASSES:
            raise Declined("the adapter cannot build %r materials" % (kind,))
        name, keys = MATERIAL_CLASSES[kind]
        make = self.material_class(name)
        if kind == "textured":
            return make(textures[m["texture"]])
        args = [float(m[k]) for k in keys]
        if kind == "cook_torrance" and positional_count(make) == len(keys):
            return make(*args)
        return make(self.color(m.get("albedo", [1.0, 1.0, 1.0])), *args)

    def objects(self, scene, materials):
        rto = self.module("RT_object")
        out = []
        for o in scene["objects"]:
            mat = materials[o["material"]]
            kind = o.get("type")
            if kind == "sphere":
                obj = self.cls("RT_object", "Sphere")(self.v3(o["center"]), float(o["radius"]), mat)
                if o.get("moving_center") is not None:
                    if not callable(getattr(obj, "add_moving", None)):
                        raise Declined("Sphere has no add_moving, which the scene's moving sphere needs")
                    obj.add_moving(self.v3(o["moving_center"]))
            elif kind == "quad":
                obj = self.cls("RT_object", "Quad")(self.v3(o["q"]), self.v3(o["u"]), self.v3(o["v"]), mat)
            elif kind == "triangle":
                Triangle = getattr(rto, "Triangle", None)
                if Triangle is None or self.make_triangle is None:
                    raise Declined("RT_object.py has no Triangle that can be built")
                # The material where the constructor takes one, else as an attribute.
                a, b, c = self.v3(o["a"]), self.v3(o["b"]), self.v3(o["c"])
                if (positional_count(Triangle) or 0) >= 4:
                    obj = Triangle(a, b, c, mat)
                else:
                    obj = self.make_triangle(a, b, c)
                    obj.material = mat
            else:
                raise Declined("the adapter cannot build %r objects" % (kind,))
            out.append(obj)
        return out

    def camera(self, scene, spp):
        image, cam, settings = scene["image"], scene["camera"], scene.get("render", {})
        c = self.cls("RT_camera", "Camera")()
        c.aspect_ratio = float(image["aspect_ratio"])
        c.img_width = int(image["width"])
        c.samples_per_pixel = spp
        c.max_depth = int(settings.get("max_depth", getattr(c, "max_depth", 1) or 1))
        c.vertical_fov = float(cam["vfov"])
        c.look_from = self.v3(cam["look_from"])
        c.look_at = self.v3(cam["look_at"])
        c.vec_up = self.v3(cam["up"])
        defocus = float(cam.get("defocus_angle", 0.0))
        focus = float(cam.get("focus_distance", 10.0))
        # Week 10's init_camera takes the lens; a camera whose init_camera takes less (an
        # earlier week's, a student's own) gets what it takes, the rest as attributes.
        n = positional_count(c.init_camera)
        if n is None or n >= 2:
            c.init_camera(defocus, focus)
        elif n == 1:
            c.focus_distance = focus
            c.init_camera(defocus)
        else:
            c.defocus_angle, c.focus_distance = defocus, focus
            c.init_camera()
        return c

    def scene(self, scene):
        Scene = self.cls("RT_scene", "Scene")
        bg = scene.get("render", {}).get("background_color")
        if bg is not None and (positional_count(Scene) or 0) >= 1:
            return Scene(self.color(bg))
        return Scene()

    def integrator(self, scene):
        Integrator = self.cls("RT_integrator", "Integrator")
        settings = scene.get("render", {})
        try:
            params = inspect.signature(Integrator).parameters
        except (TypeError, ValueError):
            params = {}
        kwargs = {}
        if "bDlight" in params and "direct_light" in settings:
            kwargs["bDlight"] = bool(settings["direct_light"])
        if "bSkyBG" in params and "background" in settings:
            kwargs["bSkyBG"] = settings["background"] == "sky"
        return Integrator(**kwargs)

    def build(self, scene, spp):
        textures = {t["name"]: self.texture(t) for t in scene.get("textures", [])}
        materials = {m["name"]: self.material(m, textures) for m in scene["materials"]}
        world = self.scene(scene)
        for obj in self.objects(scene, materials):
            world.add_object(obj)
        camera = self.camera(scene, spp)
        integrator = self.integrator(scene)
        if callable(getattr(world, "find_lights", None)):
            world.find_lights()
        jittered = scene.get("render", {}).get("sampling") == "course-jittered"
        if jittered and not callable(getattr(camera, "get_jittered_ray", None)):
            raise Declined("Camera has no get_jittered_ray, which the scene's jittered sampling needs")
        return world, camera, integrator, jittered


def seed_row(seed, x0, y, camera=None):
    """Seeds the RNGs the course draws from for one tile row: numpy's global one, random's, and
    a numpy Generator the camera keeps as `rng` (week 9's jitter)."""
    s = (int(seed) * 1000003 + y * 4099 + x0) % (1 << 32)
    import random
    random.seed(s)
    np = sys.modules.get("numpy")
    if np is not None:
        np.random.seed(s)
        if isinstance(getattr(camera, "rng", None), np.random.Generator):
            camera.rng = np.random.default_rng(s)


def render_tile(built, req):
    """The mean linear RGB of each pixel of the request's tile, row by row, as JSON text."""
    world, camera, integrator, jittered = built
    spp = int(req["spp"])
    x0, y0, x1, y1 = (int(v) for v in req["tile"])
    depth = camera.max_depth
    trace = integrator.compute_scattering
    # Week 4's compute_scattering(ray, scene) has no depth; from week 5 on it takes one.
    if positional_count(trace) == 2:
        shallow = trace
        trace = lambda ray, world, depth: shallow(ray, world)
    # The course's render_jittered: floor(sqrt(spp))^2 stratified samples, summed and divided
    # by spp all the same; else spp samples of get_ray.
    if jittered:
        m = int(spp ** 0.5)
        while (m + 1) * (m + 1) <= spp:
            m += 1
        while m * m > spp:
            m -= 1
        get = camera.get_jittered_ray
        rays = lambda i, j: (get(i, j, s_i, s_j) for s_j in range(m) for s_i in range(m))
    else:
        get = camera.get_ray
        rays = lambda i, j: (get(i, j) for _ in range(spp))
    parts = []
    inv = 1.0 / spp
    for j in range(y0, y1):
        seed_row(req.get("seed", 0), x0, j, camera)
        for i in range(x0, x1):
            r = g = b = 0.0
            for ray in rays(i, j):
                c = trace(ray, world, depth)
                e = getattr(c, "e", c)
                r += float(e[0])
                g += float(e[1])
                b += float(e[2])
            parts.append(num(r * inv))
            parts.append(num(g * inv))
            parts.append(num(b * inv))
    size = [int(getattr(camera, "img_width", 0)), int(getattr(camera, "img_height", 0))]
    return '{"tile":[%d,%d,%d,%d],"size":[%d,%d],"rgb":[%s]}' % (
        x0, y0, x1, y1, size[0], size[1], ",".join(parts))


class Renderer:
    """Answers render requests; the scene built for one request is kept for the next tiles."""

    def __init__(self, Vec3, make_triangle):
        self.Vec3 = Vec3
        self.make_triangle = make_triangle
        self.key = None
        self.built = None
        self.program = None
        self.program_module = None

    def answer(self, req):
        if req.get("program") is not None:
            return self.answer_program(req)
        key = json.dumps([req["scene"], req["spp"]], sort_keys=True)
        if key != self.key:
            self.key, self.built = None, None
            try:
                self.built = SceneBuilder(self.Vec3, self.make_triangle).build(req["scene"], int(req["spp"]))
            except Declined as d:
                return json.dumps({"declined": str(d)})
            self.key = key
        return render_tile(self.built, req)

    def answer_program(self, req):
        """A tile of the image the submission's own main.py function makes (PROGRAM_FILE)."""
        if self.program is None:
            path = os.path.join(os.path.dirname(os.path.abspath(__file__)), PROGRAM_FILE)
            if not os.path.isfile(path):
                return json.dumps({"declined": "the adapter cannot run the submission's program"})
            spec = importlib.util.spec_from_file_location("rtoracle_course_program", path)
            self.program_module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(self.program_module)
            self.program = self.program_module.ProgramRenderer()
        key = json.dumps([req["program"], req["scene"], req["spp"], req.get("seed", 0), req.get("variant")], sort_keys=True)
        try:
            return self.program.answer(req, key)
        except self.program_module.Declined as d:
            return json.dumps({"declined": str(d)})


class _Channel:
    """The answer channel: answers and anything the submission prints, in order.

    Output is batched: it is written when the adapter is about to wait for input, when many
    answers are pending, and by a watchdog thread when a call into the submission runs longer
    than a few milliseconds, so that a case that hangs never holds back earlier answers.
    """

    encoding = "utf-8"
    errors = "replace"

    def __init__(self, fd=1):
        self.fd = fd
        self.pending = []
        self.lock = threading.Lock()
        self.busy_since = 0.0

    def write(self, s):
        s = str(s)
        with self.lock:
            self.pending.append(s)
        return len(s)

    def flush(self):
        pass

    def isatty(self):
        return False

    def writable(self):
        return True

    def send(self):
        with self.lock:
            if not self.pending:
                return
            data = "".join(self.pending).encode("utf-8", "replace")
            self.pending.clear()
            view = memoryview(data)
            while view:
                n = os.write(self.fd, view)
                view = view[n:]

    def watchdog(self):
        while True:
            time.sleep(0.002)
            since = self.busy_since
            if since and self.pending and time.monotonic() - since > 0.002:
                try:
                    self.send()
                except OSError:
                    return


def dumps_compact(value):
    return json.dumps(value, separators=(",", ":"))


def lines(chan):
    """Request lines from stdin; pending output is sent before blocking on a read."""
    buf = b""
    while True:
        chan.send()
        chunk = os.read(0, 1 << 16)
        if not chunk:
            return
        buf += chunk
        parts = buf.split(b"\n")
        buf = parts.pop()
        for part in parts:
            if part.strip():
                yield part


def main():
    args = sys.argv[1:]
    submission = args[0] if args and not args[0].startswith("--") else "."
    name = "python-course " + submission
    if "--name" in args[:-1]:
        name = args[args.index("--name") + 1]
    global SUBMISSION
    SUBMISSION = submission
    if "--requires" in args[:-1]:
        REQUIRES[:] = [m for m in args[args.index("--requires") + 1].split(",") if m]
    sys.path.insert(0, os.path.abspath(submission))
    if "--prints-to-stderr" in args:
        # Grading: what the submission prints (even from C or a child process) goes to stderr,
        # never among the answers, which keep a descriptor of their own.
        chan = _Channel(os.dup(1))
        os.dup2(2, 1)
        sys.stdout = sys.stderr
    else:
        # Prints of the submission keep their place among the answers (the harness reports
        # them as protocol errors).
        chan = _Channel()
        sys.stdout = chan
    # It cannot read (steal) the requests: they are read from the descriptor directly.
    sys.stdin = open(os.devnull)
    out = chan
    loads = json.loads
    requests = lines(chan)

    if next(requests, None) is None:
        return
    hello = {"name": name, "protocol": 1, "shapes": ["sphere", "quad"]}
    functions = load_functions()
    if functions is not None:
        hello["ops"] = ["intersect"] + list(functions.OPS)
    try:
        import RT_utility
        import RT_ray
        import RT_object
    except BaseException as exc:  # SyntaxError, ImportError, SystemExit, ...
        # Every shape, so every case (a triangle too) gets the import error, not "unsupported".
        hello["shapes"].append("triangle")
        hello["error"] = loads(error_json(exc))
        out.write(json.dumps(hello) + "\n")
        # Keep answering so every intersection gets the import error; a function request is
        # still answered by the driver, which imports only what it needs (a module that failed
        # here fails the requests that need it, and they name it).
        err = json.dumps(hello["error"])
        for line in requests:
            req = None
            try:
                req = loads(line)
                rid = json.dumps(req.get("id"))
            except Exception:
                rid = "null"
            op = req.get("op") if isinstance(req, dict) else None
            if functions is not None and op in functions.OPS:
                try:
                    ans = dumps_compact(functions.answer(req))
                    out.write('{"id":' + rid + ',"result":' + ans + "}\n")
                except BaseException as fexc:
                    out.write('{"id":' + rid + ',"error":' + error_json(fexc) + "}\n")
                chan.send()
                continue
            out.write('{"id":' + rid + ',"error":' + err + "}\n")
        chan.send()
        return

    Vec3 = RT_utility.Vec3
    Interval = RT_utility.Interval
    Ray = RT_ray.Ray
    Sphere = getattr(RT_object, "Sphere", None)
    Quad = getattr(RT_object, "Quad", None)
    Triangle = getattr(RT_object, "Triangle", None)
    # The week-4 Triangle is an empty stub: support it only when it can make one.
    make_triangle = triangle_maker(Triangle, Vec3)
    if make_triangle is not None:
        hello["shapes"].append("triangle")
    hello.setdefault("ops", ["intersect"]).extend(["render", "render_program"])
    renderer = Renderer(Vec3, make_triangle)
    out.write(json.dumps(hello) + "\n")
    threading.Thread(target=chan.watchdog, daemon=True).start()
    monotonic = time.monotonic
    pending = chan.pending

    def v3(a):
        return Vec3(float(a[0]), float(a[1]), float(a[2]))

    decode = json.JSONDecoder().raw_decode
    dumps = json.dumps

    for line in requests:
        rid = "null"
        try:
            req = decode(line.decode())[0]
            rid = req["id"]
            if type(rid) is str and rid.isprintable() and '"' not in rid and "\\" not in rid:
                rid = '"' + rid + '"'
            else:
                rid = dumps(rid)
            if req.get("op") == "render":
                chan.busy_since = monotonic()
                ans = '{"id":' + rid + ',"result":' + renderer.answer(req) + "}\n"
                chan.busy_since = 0.0
                out.write(ans)
                chan.send()
                continue
            op = req.get("op", "intersect")
            if op != "intersect":
                chan.busy_since = monotonic()
                if functions is None or op not in functions.OPS:
                    raise ValueError("unknown request op %r" % (op,))
                ans = '{"id":' + rid + ',"result":' + dumps(functions.answer(req), separators=(",", ":")) + "}\n"
                chan.busy_since = 0.0
                out.write(ans)
                if len(pending) > 256 or b'"sync":true' in line[:16]:
                    chan.send()
                continue
            s = req["shape"]
            kind = s["type"]
            r = req["ray"]
            iv = req["interval"]
            chan.busy_since = monotonic()
            if kind == "sphere":
                obj = Sphere(v3(s["center"]), float(s["radius"]), None)
            elif kind == "quad":
                obj = Quad(v3(s["q"]), v3(s["u"]), v3(s["v"]), None)
            else:
                obj = make_triangle(v3(s["a"]), v3(s["b"]), v3(s["c"]))
            hit = obj.intersect(
                Ray(v3(r["origin"]), v3(r["direction"])),
                Interval(float(iv[0]), float(iv[1])),
            )
            if hit is None or hit is False:
                ans = '{"id":' + rid + ',"hit":false}\n'
            else:
                ans = (
                    '{"id":' + rid
                    + ',"hit":true,"t":' + num(hit.getT())
                    + ',"point":' + vec(hit.getP())
                    + ',"normal":' + vec(hit.getNormal())
                    + ',"front_face":' + truth(hit.front_face)
                    + "}\n"
                )
        except BaseException as exc:  # anything the submission raises, SystemExit included
            ans = '{"id":' + rid + ',"error":' + error_json(exc) + "}\n"
        chan.busy_since = 0.0
        out.write(ans)
        if len(pending) > 256 or b'"sync":true' in line[:16]:
            chan.send()
    chan.send()


main()
