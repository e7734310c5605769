"""rtoracle's driver of the course's functions of weeks 5 to 10 (stdlib only; the submission's
own modules bring numpy and Pillow).

The course adapter (course_adapter.py) loads this file from its own folder and hands it every
request whose "op" is one of OPS (docs/PROTOCOL.md, "Function requests"). `answer(request)`
calls the submission's own function, unmodified, and returns the answer's "result" object; an
exception (the submission's, or NotFound / BadReturn raised here) becomes the
answer's "error".

Finding functions. The course (weeks 5 to 10, its real code) puts reflect, refract, schlick and
halfvector in RT_material, the samplers as static methods of RT_utility.Vec3
(Vec3.random_vec3_unit(), Vec3.random_vec3_in_unit_disk(), Vec3.random_cosine_hemisphere_on_z()),
ONB in RT_utility, the materials in RT_material, Diffuse_light in RT_light, the textures in
RT_texture, Scene in RT_scene, Integrator in RT_integrator, Camera in RT_camera; a student may
put them elsewhere. Each is looked for in every RT_*.py module of the submission (RT_utility
first; RT_renderer and RT_pbar are never imported: they need progressbar2), and a function also
as a static method of Vec3. What cannot be found is an error of type NotFound that names where it
looked.

Imports. Each RT_*.py module is imported on its own, the first time a request needs one: a module
that fails to import (a helper importing a package the grader lacks, say) is remembered with its
file, line and the missing package, and fails only the requests that need what it would have
defined (their NotFound names it); the others are answered.

Each week's API. A request drives the version of a function the submission has: the integrator's
compute_scattering with or without its depth (week 4's takes two arguments), ONB.local with one
Vec3 (the course's) or three numbers and its axes as methods (the course's u(), v(), w()) or
attributes, the camera's frame as camera_frame_u/v/w (the course's) or u/v/w, its defocus radius
as defocus_radius or the length of defocus_disk_u, CookTorrance with or without the albedo first
(week 8's skeleton has it). Where a submission keeps the course's behaviour through another
convention (init_camera taking the lens's aperture instead of its defocus angle: the course's
lens is given as the aperture 2 focus tan(angle / 2)), the answer lists it in "departures"
(codes rtoracle words: "aperture").

Random numbers. A request's "replace" object steers the course's random numbers for the call:
"random_double" gives numbers u in [0, 1] that the course's module-level random_double(lo, hi)
returns as lo + u (hi - lo), in turn, replaced in every module that holds it; the course's Vec3
static helpers (random_vec3_unit, random_vec3_in_unit_disk, random_cosine_hemisphere_on_z) draw
through it, so they are steered too. "rng" gives the numbers of the camera's own numpy Generator.
Past the values given, numbers come from the seeded generators (see Replaced). The answer never
says what was drawn: the grader judges what the code returned (docs/weekly-checks.md).
Sampling requests ("n", "seed") and steered ones ("seed") seed numpy's global generator,
Python's random and every np.random.default_rng() made during the call with the seed instead.
"""

import glob
import inspect
import math
import os
import sys

# Modules that are never imported: the renderer needs progressbar2, main.py renders.
SKIPPED = ("RT_renderer", "RT_pbar")
# The course's own placement of things, searched first, in this order.
PREFERRED = ("RT_utility", "RT_material", "RT_texture", "RT_object", "RT_scene",
             "RT_integrator", "RT_camera", "RT_ray")

OPS = ("reflect", "refract", "schlick", "halfvector", "sphere_uv", "quad_uv", "texture",
       "brdf", "scatter", "onb", "move_sphere", "intersect_at_time", "camera", "occlusion",
       "shade", "sample_unit_vector", "sample_cosine_hemisphere", "sample_unit_disk",
       "sample_scatter", "sample_camera_ray")

# Most samples one request may ask for (an answer line stays under 1 MiB).
MAX_SAMPLES = 2000


class NotFound(Exception):
    """What the request needs is not in the submission."""


class BadReturn(Exception):
    """A function returned something the course's never returns (None from a stub, say)."""


_state = {"dir": ".", "modules": None, "failed": None}


def set_submission(folder):
    _state["dir"] = folder
    _state["modules"] = None
    _state["failed"] = None


def import_failure(name, exc):
    """Why module `name` failed to import, in words: the file and line where it raised (the
    deepest frame in the submission's folder) and, for a missing module, the package."""
    import traceback
    folder = os.path.abspath(_state["dir"])
    own = os.path.abspath(__file__)
    where = None
    for frame in traceback.extract_tb(exc.__traceback__):
        path = os.path.abspath(frame.filename)
        base = os.path.basename(path)
        # The adapter and this driver sit beside the submission's files: not its code.
        if path == own or base.startswith("rtoracle_") or base == "course_adapter.py":
            continue
        if os.path.dirname(path) == folder:
            where = "%s, line %d" % (base, frame.lineno)
    if isinstance(exc, SyntaxError) and getattr(exc, "filename", None):
        where = "%s, line %s" % (os.path.basename(exc.filename), exc.lineno)
    if isinstance(exc, ModuleNotFoundError) and getattr(exc, "name", None):
        what = "imports %s, which the grader does not provide" % exc.name.split(".")[0]
        top = exc.name.split(".")[0]
        if top.startswith("RT_") and not os.path.exists(os.path.join(folder, top + ".py")):
            what = "imports %s, which is not in the submission folder" % top
    else:
        try:
            what = "raises %s: %s" % (type(exc).__name__, str(exc)[:300])
        except Exception:
            what = "raises %s" % type(exc).__name__
    if where is None:
        return "%s.py could not be imported: it %s" % (name, what)
    return "%s.py could not be imported: %s %s" % (name, where, what)


def modules():
    """The submission's RT_*.py modules that import: the course's order first, then the others.
    A module that fails to import is left out and remembered (`import_failures`)."""
    if _state["modules"] is None:
        names = sorted(
            os.path.basename(p)[:-3]
            for p in glob.glob(os.path.join(_state["dir"], "RT_*.py"))
        )
        names = [n for n in names if n.isidentifier() and n not in SKIPPED]
        ordered = [n for n in PREFERRED if n in names] + [n for n in names if n not in PREFERRED]
        found = []
        failed = []
        for name in ordered:
            try:
                found.append((name, __import__(name)))
            except BaseException as exc:  # SyntaxError, ImportError, SystemExit, ...
                sys.modules.pop(name, None)
                failed.append((name, import_failure(name, exc)))
        _state["modules"] = found
        _state["failed"] = failed
    return _state["modules"]


def import_failures():
    """`(module, why)` of the submission's modules that failed to import."""
    modules()
    return _state["failed"] or []


def module(name):
    for n, m in modules():
        if n == name:
            return m
    return None


def where_looked():
    return ", ".join(n + ".py" for n, _ in modules()) or "no RT_*.py module"


def failed_imports():
    """"; " and the modules that could not be imported, in words, or ""."""
    failed = import_failures()
    return "".join("; " + why for _, why in failed)


def find_function(name, aliases=(), course_home="RT_utility"):
    """A module-level function of the submission (or a static method of Vec3)."""
    names = (name,) + tuple(aliases)
    for _, m in modules():
        for n in names:
            f = getattr(m, n, None)
            if callable(f) and not inspect.isclass(f):
                return f
    vec3 = getattr(module("RT_utility"), "Vec3", None)
    for n in names:
        f = getattr(vec3, n, None) if vec3 is not None else None
        if callable(f):
            return f
    raise NotFound(
        "no function %s in the submission (looked in %s, and for Vec3.%s); the course defines "
        "it in %s.py%s" % (name, where_looked(), name, course_home, failed_imports())
    )


def find_class(names, course_home):
    if isinstance(names, str):
        names = (names,)
    for _, m in modules():
        for n in names:
            c = getattr(m, n, None)
            if inspect.isclass(c):
                return c
    raise NotFound(
        "no class %s in the submission (looked in %s); the course defines it in %s.py%s"
        % (names[0], where_looked(), course_home, failed_imports())
    )


def method(obj, name, cls_name):
    f = getattr(obj, name, None)
    if not callable(f):
        raise NotFound("%s has no method %s" % (cls_name, name))
    return f


def positional_count(f):
    """How many positional parameters f takes (self excluded), or None when it cannot be read."""
    try:
        params = list(inspect.signature(f).parameters.values())
    except (TypeError, ValueError):
        return None
    if any(p.kind == p.VAR_POSITIONAL for p in params):
        return None
    return len([p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)])


# ---------------------------------------------------------------------------------------------
# Values in and out.

def vec3(a):
    Vec3 = find_class("Vec3", "RT_utility")
    return Vec3(float(a[0]), float(a[1]), float(a[2]))


def color(a):
    Color = find_class("Color", "RT_utility")
    return Color(float(a[0]), float(a[1]), float(a[2]))


def number(x):
    """A float for JSON: non-finite numbers as the protocol's strings."""
    x = float(x)
    if x != x:
        return "nan"
    if x == math.inf:
        return "inf"
    if x == -math.inf:
        return "-inf"
    return x


def num_in(x):
    if isinstance(x, str):
        return float(x)
    return float(x)


def out_vec(v, what):
    """A Vec3 or Color (components in .e), a sequence or a numpy array, as three numbers."""
    if v is None:
        raise BadReturn("%s returned None" % what)
    e = getattr(v, "e", v)
    try:
        if len(e) != 3:
            raise BadReturn("%s returned %d components, not 3" % (what, len(e)))
        return [number(e[0]), number(e[1]), number(e[2])]
    except (TypeError, ValueError):
        raise BadReturn("%s returned %s, not a vector" % (what, type(v).__name__))


def out_num(x, what):
    if x is None:
        raise BadReturn("%s returned None" % what)
    try:
        return number(x)
    except (TypeError, ValueError):
        raise BadReturn("%s returned %s, not a number" % (what, type(x).__name__))


def out_bool(x, what):
    if x is None:
        raise BadReturn("%s returned None" % what)
    return bool(x)


def make_ray(spec):
    Ray = find_class("Ray", "RT_ray")
    o, d = vec3(spec["origin"]), vec3(spec["direction"])
    time = spec.get("time")
    if time is None:
        return Ray(o, d)
    count = positional_count(Ray.__init__)
    if count is not None and count < 4:
        if float(time) == 0.0:
            return Ray(o, d)
        raise NotFound("Ray takes no time (the course adds Ray(vOrigin, vDir, fTime) in week 10)")
    return Ray(o, d, float(time))


def make_interval(a):
    Interval = find_class("Interval", "RT_utility")
    return Interval(num_in(a[0]), num_in(a[1]))


def make_hit(spec, ray, material):
    """A hit record as the course's intersect makes one: Hitinfo(P, outward normal, t, material),
    then set_face_normal(ray, outward) and set_uv(u, v)."""
    Hitinfo = find_class(("Hitinfo", "HitInfo", "HitRecord"), "RT_utility")
    outward = vec3(spec["normal"])
    hit = Hitinfo(vec3(spec["point"]), outward, float(spec.get("t", 1.0)), material)
    setter = getattr(hit, "set_face_normal", None)
    if callable(setter):
        setter(ray, outward)
    uv = spec.get("uv")
    if uv is not None:
        set_uv = getattr(hit, "set_uv", None)
        if callable(set_uv):
            set_uv(float(uv[0]), float(uv[1]))
        else:
            hit.u, hit.v = float(uv[0]), float(uv[1])
    return hit


def hit_uv(hit):
    get = getattr(hit, "getUV", None)
    if callable(get):
        uv = get()
    else:
        uv = (getattr(hit, "u", None), getattr(hit, "v", None))
    return [out_num(uv[0], "the hit's u"), out_num(uv[1], "the hit's v")]


def picture_file(spec):
    """Writes the request's picture as a PNG in the working folder; its name."""
    import numpy as np
    from PIL import Image
    w, h = int(spec["width"]), int(spec["height"])
    data = bytes(int(b) for b in spec["rgb"])
    name = "rtoracle_texture_%dx%d_%08x.png" % (w, h, hash(data) & 0xFFFFFFFF)
    if not os.path.exists(name):
        px = np.frombuffer(data, dtype=np.uint8).reshape(h, w, 3)
        Image.fromarray(px).save(name)
    return name


def make_texture(spec):
    kind = spec["type"]
    if kind == "solid":
        return find_class(("SolidColor", "Solid_color", "SolidTexture"), "RT_texture")(
            color(spec["color"]))
    if kind == "checker":
        return find_class(("CheckerTexture", "Checker_texture", "Checker"), "RT_texture")(
            float(spec["scale"]), color(spec["even"]), color(spec["odd"]))
    if kind == "image":
        return find_class(("ImageTexture", "Image_texture"), "RT_texture")(picture_file(spec))
    raise ValueError("unknown texture type %r" % kind)


def make_material(spec):
    if spec is None:
        return None
    kind = spec["type"]
    home = "RT_material"
    if kind == "lambertian":
        return find_class("Lambertian", home)(color(spec["albedo"]))
    if kind == "textured":
        return find_class(("TextureColor", "Texture_color", "Textured"), home)(
            make_texture(spec["texture"]))
    if kind == "mirror":
        return find_class("Mirror", home)(color(spec["albedo"]))
    if kind == "dielectric":
        return find_class("Dielectric", home)(color(spec["albedo"]), float(spec["ior"]))
    if kind == "metal":
        return find_class("Metal", home)(color(spec["albedo"]), float(spec["roughness"]))
    if kind == "diffuse_light":
        return find_class(("Diffuse_light", "DiffuseLight", "Diffuse_Light"), "RT_light")(
            color(spec["color"]))
    if kind in ("phong", "blinn"):
        cls = find_class("Phong" if kind == "phong" else "Blinn", home)
        return cls(color(spec["albedo"]), float(spec["kd"]), float(spec["ks"]),
                   float(spec["alpha"]))
    if kind == "cook_torrance":
        cls = find_class(("CookTorrance", "Cook_Torrance", "Cooktorrance"), home)
        args = [float(spec["kd"]), float(spec["ks"]), float(spec["alpha"]), float(spec["ior"])]
        # Week 8's constructor takes the albedo first; weeks 9 and 10's do not.
        if positional_count(cls.__init__) == 6:
            args.insert(0, color(spec.get("albedo", [1.0, 1.0, 1.0])))
        return cls(*args)
    raise ValueError("unknown material type %r" % kind)


def make_object(spec):
    material = make_material(spec.get("material"))
    kind = spec["type"]
    if kind == "sphere":
        s = find_class("Sphere", "RT_object")(vec3(spec["center"]), float(spec["radius"]),
                                              material)
        if spec.get("moving_to") is not None:
            method(s, "add_moving", "Sphere")(vec3(spec["moving_to"]))
        return s
    if kind == "quad":
        return find_class("Quad", "RT_object")(vec3(spec["q"]), vec3(spec["u"]),
                                               vec3(spec["v"]), material)
    raise ValueError("unknown object type %r" % kind)


# The background colour of the course's scenes (Scene()'s default, cBgcolor).
COURSE_BACKGROUND = (0.01, 0.01, 0.01)


def make_scene(objects):
    """The course's Scene of `objects`, its background colour given explicitly as the course's
    scenes have it (0.01 grey), so an integrator that returns the scene's own colour on a miss
    answers what the course's does whatever the class's default."""
    cls = find_class("Scene", "RT_scene")
    count = positional_count(cls.__init__)
    if count is not None and count >= 2:
        scene = cls(color(COURSE_BACKGROUND))
    else:
        scene = cls()
    add = method(scene, "add_object", "Scene")
    for o in objects:
        add(make_object(o))
    find_lights = getattr(scene, "find_lights", None)
    if callable(find_lights):
        find_lights()
    return scene


# ---------------------------------------------------------------------------------------------
# Replacing the random functions for one call.

class _Stream:
    """The values a request gives for one random source, in order; None past them (the caller
    then draws from the seeded generator instead)."""

    def __init__(self, values):
        self.values = [float(v) for v in values]
        self.drawn = 0

    def take(self):
        self.drawn += 1
        if self.drawn <= len(self.values):
            return self.values[self.drawn - 1]
        return None


class _SteeredGenerator:
    """Stands for the camera's numpy Generator (week 9's `camera_rng`): .random() and
    .uniform() return the request's values, then the real generator's."""

    def __init__(self, stream, real):
        self._stream = stream
        self._real = real

    def random(self, *args, **kwargs):
        if args or kwargs:
            return self._real.random(*args, **kwargs)
        u = self._stream.take()
        return self._real.random() if u is None else u

    def uniform(self, low=0.0, high=1.0, size=None):
        if size is not None:
            return self._real.uniform(low, high, size)
        u = self._stream.take()
        return self._real.uniform(low, high) if u is None else low + u * (high - low)

    def __getattr__(self, name):
        return getattr(self._real, name)


class Replaced:
    """Steers the course's random numbers for a `with` block.

    `spec` maps "random_double" to numbers u in [0, 1]: the course's module-level
    `random_double(min, max)` returns min + u (max - min) for each in turn. It is replaced in
    every module of the submission that holds it (`rtu.random_double`, a `from RT_utility import
    random_double`), and since the course's `Vec3` static helpers (`random_vec3_unit`,
    `random_vec3_in_unit_disk`, `random_cosine_hemisphere_on_z`, ...) call the module-level
    name, they are steered too, rejection loops included. "rng" gives the numbers of the
    camera's own numpy Generator (`generator(real)` wraps one). Past the values given, draws come
    from the seeded generator (the original `random_double`, numpy's global one): code that
    draws more, or otherwise, than the course's still runs, and is judged by what it does.
    """

    def __init__(self, spec):
        self.spec = spec or {}
        self.undo = []
        self.streams = {}

    def __enter__(self):
        for name, values in self.spec.items():
            if name not in ("random_double", "rng"):
                raise ValueError("cannot replace %r" % name)
            self.streams[name] = _Stream(values)
        if "random_double" in self.streams:
            self._steer_random_double(self.streams["random_double"])
        return self

    def _steer_random_double(self, stream):
        util = module("RT_utility")
        original = getattr(util, "random_double", None) if util is not None else None

        def fallback(lo, hi):
            if callable(original):
                return original(lo, hi)
            import numpy as np
            return np.random.uniform(lo, hi)

        def random_double(min=0.0, max=1.0):
            u = stream.take()
            if u is None:
                return fallback(min, max)
            return min + u * (max - min)

        swapped = False
        for _, m in modules():
            value = getattr(m, "random_double", None)
            if value is not None and (value is original or m is util):
                self.undo.append((m, value))
                setattr(m, "random_double", random_double)
                swapped = True
        if not swapped and util is not None:
            self.undo.append((util, None))
            setattr(util, "random_double", random_double)

    def generator(self, real):
        """The camera's Generator `real`, steered by "rng" (itself when the spec has none)."""
        stream = self.streams.get("rng")
        return real if stream is None else _SteeredGenerator(stream, real)

    def __exit__(self, *exc):
        for m, value in reversed(self.undo):
            if value is None:
                try:
                    delattr(m, "random_double")
                except AttributeError:
                    pass
            else:
                setattr(m, "random_double", value)
        return False


class Seeded:
    """Seeds numpy's global generator, Python's random and new default_rng()s for a block."""

    def __init__(self, seed):
        self.seed = int(seed) & 0xFFFFFFFF

    def __enter__(self):
        import random
        import numpy as np
        np.random.seed(self.seed)
        random.seed(self.seed)
        self.np = np
        self.original = np.random.default_rng
        made = [0]
        original, seed = self.original, self.seed

        def default_rng(*args, **kwargs):
            made[0] += 1
            return original((seed + 7919 * made[0]) & 0xFFFFFFFF)

        np.random.default_rng = default_rng
        return self

    def __exit__(self, *exc):
        self.np.random.default_rng = self.original
        return False


# ---------------------------------------------------------------------------------------------
# The requests.

def op_reflect(req):
    f = find_function("reflect", (), "RT_material")
    return {"vector": out_vec(f(vec3(req["v"]), vec3(req["n"])), "reflect")}


def op_refract(req):
    f = find_function("refract", (), "RT_material")
    with Seeded(req.get("seed", 0)), Replaced({"random_double": req.get("random", [])}):
        out = f(vec3(req["v"]), vec3(req["n"]), float(req["ratio"]))
    return {"vector": out_vec(out, "refract")}


def op_schlick(req):
    f = find_function("schlick", ("reflectance",), "RT_material")
    return {"value": out_num(f(float(req["cosine"]), float(req["ratio"])), "schlick")}


def op_halfvector(req):
    f = find_function("halfvector", ("half_vector",), "RT_material")
    return {"vector": out_vec(f(vec3(req["v"]), vec3(req["l"])), "halfvector")}


def op_sphere_uv(req):
    Sphere = find_class("Sphere", "RT_object")
    s = Sphere(vec3([0, 0, 0]), 1.0, None)
    get_uv = getattr(s, "get_uv", None)
    if not callable(get_uv):
        get_uv = find_function("get_uv", ("get_sphere_uv",), "RT_object")
    uv = get_uv(vec3(req["normal"]))
    if uv is None:
        raise BadReturn("Sphere.get_uv returned None")
    return {"uv": [out_num(uv[0], "get_uv's u"), out_num(uv[1], "get_uv's v")]}


def intersect_answer(hit):
    if hit is None or hit is False:
        return {"hit": False}
    return {"hit": True, "t": out_num(hit.getT(), "getT()"),
            "point": out_vec(hit.getP(), "getP()"),
            "normal": out_vec(hit.getNormal(), "getNormal()"),
            "front_face": bool(hit.front_face), "uv": hit_uv(hit)}


def op_quad_uv(req):
    q = make_object(dict(req["quad"], type="quad"))
    return intersect_answer(q.intersect(make_ray(req["ray"]), make_interval(req["interval"])))


def op_intersect_at_time(req):
    s = make_object(dict(req["sphere"], type="sphere"))
    return intersect_answer(s.intersect(make_ray(req["ray"]), make_interval(req["interval"])))


def op_move_sphere(req):
    s = make_object({"type": "sphere", "center": req["center"], "radius": 1.0,
                     "moving_to": req["moving_to"]})
    moved = method(s, "move_sphere", "Sphere")(float(req["time"]))
    return {"center": out_vec(moved, "move_sphere")}


def op_texture(req):
    t = make_texture(req["texture"])
    uv = req["uv"]
    value = method(t, "tex_value", type(t).__name__)(float(uv[0]), float(uv[1]),
                                                      vec3(req["point"]))
    return {"color": out_vec(value, type(t).__name__ + ".tex_value")}


def op_brdf(req):
    m = make_material(req["material"])
    view = make_ray(req["view"])
    light = make_ray(req["light"])
    hit = make_hit(req["hit"], view, m)
    value = method(m, "BRDF", type(m).__name__)(view, light, hit)
    what = type(m).__name__ + ".BRDF"
    if value is None:
        raise BadReturn("%s returned None" % what)
    if isinstance(value, (int, float)) or type(value).__name__.startswith("float"):
        return {"value": out_num(value, what)}
    return {"color": out_vec(value, what)}


def scatter_once(m, ray, hit, what):
    s = method(m, "scattering", type(m).__name__)(ray, hit)
    if s is None:
        return None
    r = getattr(s, "scattered_ray", None)
    a = getattr(s, "attenuation_color", None)
    if r is None or a is None:
        raise BadReturn("%s returned a %s without scattered_ray and attenuation_color"
                        % (what, type(s).__name__))
    get_time = getattr(r, "getTime", None)
    time = get_time() if callable(get_time) else getattr(r, "time", 0.0)
    return (out_vec(r.getOrigin(), what + "'s ray origin"),
            out_vec(r.getDirection(), what + "'s ray direction"),
            out_num(time if time is not None else 0.0, what + "'s ray time"),
            out_vec(a, what + "'s attenuation"))


def op_scatter(req):
    m = make_material(req["material"])
    ray = make_ray(req["ray"])
    hit = make_hit(req["hit"], ray, m)
    what = type(m).__name__ + ".scattering"
    with Seeded(req.get("seed", 0)), Replaced(req.get("replace")):
        out = scatter_once(m, ray, hit, what)
    if out is None:
        return {"scattered": False}
    return {"scattered": True, "origin": out[0], "direction": out[1], "time": out[2],
            "attenuation": out[3]}


def onb_axis(o, name):
    """An ONB's axis: the course's method u() (or an attribute u)."""
    a = getattr(o, name, None)
    if callable(a) and not hasattr(a, "e"):
        a = a()
    return out_vec(a, "ONB." + name)


def op_onb(req):
    cls = find_class(("ONB", "Onb", "OrthonormalBasis"), "RT_utility")
    o = cls()
    method(o, "build_from_w", cls.__name__)(vec3(req["w"]))
    local = method(o, "local", cls.__name__)
    # The course's local(self, val) takes one Vec3; some take the three numbers.
    if positional_count(local) == 3:
        out = local(*(float(c) for c in req["local"]))
    else:
        out = local(vec3(req["local"]))
    return {"u": onb_axis(o, "u"), "v": onb_axis(o, "v"), "w": onb_axis(o, "w"),
            "local": out_vec(out, "ONB.local")}


CAMERA_FIELDS = (("img_width", "width", int), ("aspect_ratio", "aspect_ratio", float),
                 ("samples_per_pixel", "spp", int), ("vertical_fov", "vfov", float),
                 ("look_from", "look_from", vec3), ("look_at", "look_at", vec3),
                 ("vec_up", "vup", vec3), ("max_depth", "max_depth", int))


def first_parameter(f):
    """The name of f's first parameter after self, or ""."""
    try:
        params = [p for p in inspect.signature(f).parameters.values()
                  if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    except (TypeError, ValueError):
        return ""
    return params[0].name if params else ""


def make_camera(spec, departures=None):
    """The course's Camera with the request's fields set before init_camera(defocus_angle,
    focus_distance), as every main.py does. A camera whose init_camera takes the lens's
    aperture (week 10's task 2: "DoF by using an 'aperture' parameter instead of
    'defocus_angle'") is given the course's lens as its aperture, 2 focus tan(angle / 2)."""
    cam = find_class("Camera", "RT_camera")()
    for attr, key, conv in CAMERA_FIELDS:
        if key in spec:
            setattr(cam, attr, conv(spec[key]))
    init = method(cam, "init_camera", "Camera")
    angle = float(spec.get("defocus_angle", 0.0))
    focus = float(spec.get("focus_distance", 10.0))
    if "aperture" in first_parameter(init).lower():
        init(2.0 * focus * math.tan(math.radians(angle) / 2.0), focus)
        if departures is not None:
            departures.append("aperture")
    else:
        init(angle, focus)
    return cam


def camera_attr(cam, names, what):
    for n in names:
        v = getattr(cam, n, None)
        if v is not None:
            return v
    raise NotFound("the camera has no %s (looked for %s)" % (what, ", ".join(names)))


def defocus_radius(cam):
    """The camera's defocus radius: an attribute defocus_radius, else the length of
    defocus_disk_u (the course keeps the radius only as defocus_disk_u and defocus_disk_v)."""
    r = getattr(cam, "defocus_radius", None)
    if r is not None:
        return out_num(r, "defocus_radius")
    du = getattr(cam, "defocus_disk_u", None)
    if du is None:
        raise NotFound("the camera has no defocus radius (looked for defocus_radius and "
                       "defocus_disk_u)")
    e = out_vec(du, "defocus_disk_u")
    return math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])


def op_camera(req):
    departures = []
    cam = make_camera(req["camera"], departures)
    answer = {
        "center": out_vec(camera_attr(cam, ("center", "camera_center"), "centre"), "center"),
        "u": out_vec(camera_attr(cam, ("camera_frame_u", "u"), "u"), "camera_frame_u"),
        "v": out_vec(camera_attr(cam, ("camera_frame_v", "v"), "v"), "camera_frame_v"),
        "w": out_vec(camera_attr(cam, ("camera_frame_w", "w"), "w"), "camera_frame_w"),
        "pixel00": out_vec(camera_attr(cam, ("pixel00_location", "pixel00_loc"), "pixel00"),
                           "pixel00_location"),
        "pixel_du": out_vec(camera_attr(cam, ("pixel_du", "pixel_delta_u"), "pixel_du"),
                            "pixel_du"),
        "pixel_dv": out_vec(camera_attr(cam, ("pixel_dv", "pixel_delta_v"), "pixel_dv"),
                            "pixel_dv"),
        "defocus_radius": defocus_radius(cam),
        "height": int(camera_attr(cam, ("img_height", "image_height"), "image height")),
    }
    if departures:
        answer["departures"] = departures
    return answer


def op_occlusion(req):
    scene = make_scene(req["objects"])
    f = method(scene, "find_occlusion", "Scene")
    return {"occluded": out_bool(f(make_ray(req["ray"]), make_interval(req["interval"])),
                                 "Scene.find_occlusion")}


def make_integrator(spec):
    cls = find_class("Integrator", "RT_integrator")
    spec = spec or {}
    count = positional_count(cls.__init__)
    if count is not None and count >= 3:
        return cls(bool(spec.get("direct_light", True)), bool(spec.get("sky", False)))
    return cls()


def op_shade(req):
    scene = make_scene(req["objects"])
    integrator = make_integrator(req.get("integrator"))
    f = method(integrator, "compute_scattering", "Integrator")
    with Seeded(req.get("seed", 0)):
        # Week 4's compute_scattering(ray, scene) has no depth; weeks 5 to 10 take it.
        if positional_count(f) == 2:
            value = f(make_ray(req["ray"]), scene)
        else:
            value = f(make_ray(req["ray"]), scene, int(req.get("depth", 1)))
    return {"color": out_vec(value, "Integrator.compute_scattering")}


def sample_count(req):
    n = int(req["n"])
    if not 1 <= n <= MAX_SAMPLES:
        raise ValueError("n must be 1 to %d" % MAX_SAMPLES)
    return n


def op_sample_unit_vector(req):
    return sample_vectors(req, "random_vec3_unit", ("random_unit_vector", "random_vec3_unit_vector"))


def op_sample_cosine_hemisphere(req):
    return sample_vectors(req, "random_cosine_hemisphere_on_z", ("random_cosine_direction",))


def op_sample_unit_disk(req):
    return sample_vectors(req, "random_in_unit_disk", ("random_vec3_in_unit_disk",))


def sample_vectors(req, name, aliases):
    f = find_function(name, aliases)
    n = sample_count(req)
    with Seeded(req["seed"]):
        samples = [out_vec(f(), name) for _ in range(n)]
    return {"samples": samples}


def op_sample_scatter(req):
    m = make_material(req["material"])
    ray = make_ray(req["ray"])
    hit = make_hit(req["hit"], ray, m)
    what = type(m).__name__ + ".scattering"
    n = sample_count(req)
    samples = []
    with Seeded(req["seed"]):
        for _ in range(n):
            s = scatter_once(m, ray, hit, what)
            samples.append(None if s is None else s[0] + s[1] + s[3])
    return {"samples": samples}


def steer_camera(cam, steered):
    """Steers the camera's own numpy Generator (week 9's camera_rng) by the request's "rng"."""
    import numpy as np
    for name in ("camera_rng", "rng"):
        real = getattr(cam, name, None)
        if isinstance(real, np.random.Generator):
            setattr(cam, name, steered.generator(real))


def op_sample_camera_ray(req):
    n = sample_count(req)
    samples = []
    departures = []
    with Seeded(req["seed"]), Replaced(req.get("replace")) as steered:
        cam = make_camera(req["camera"], departures)
        steer_camera(cam, steered)
        i, j = (int(c) for c in req["pixel"])
        stratum = req.get("stratum")
        if stratum is not None:
            f = method(cam, "get_jittered_ray", "Camera")
            args = (i, j, int(stratum[0]), int(stratum[1]))
            what = "Camera.get_jittered_ray"
        else:
            f = method(cam, "get_ray", "Camera")
            args = (i, j)
            what = "Camera.get_ray"
        for _ in range(n):
            r = f(*args)
            if r is None:
                raise BadReturn("%s returned None" % what)
            get_time = getattr(r, "getTime", None)
            time = get_time() if callable(get_time) else getattr(r, "time", 0.0)
            samples.append(out_vec(r.getOrigin(), what + "'s origin")
                           + out_vec(r.getDirection(), what + "'s direction")
                           + [out_num(time if time is not None else 0.0, what + "'s time")])
    if departures:
        return {"samples": samples, "departures": departures}
    return {"samples": samples}


HANDLERS = {name: globals()["op_" + name] for name in OPS}


def answer(req):
    """The result object of a function request (raises what the submission raises)."""
    return HANDLERS[req["op"]](req)
