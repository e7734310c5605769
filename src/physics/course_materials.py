
# ---------------------------------------------------------------------------------------------
# rtoracle's material requests for the course's BRDF materials (docs/PROTOCOL.md, "Material
# requests"; `rtoracle physics`). This text is appended to the functions driver above when it is
# written into the sandbox (src/candidate/command.rs), so it extends OPS and answer() and uses
# the driver's helpers (make_material, make_ray, make_hit, modules, Seeded).
#
# material_sample runs the submission's own Material.scattering(ray, hit) with random_double
# returning the row's four numbers, then numbers from a generator seeded by the row (week 8's
# random_vec3_unit rejects points of the cube and may need more than four). The weight is what
# the course's integrator multiplies the scattered radiance by: BRDF(ray, scattered) times
# n . d, 0 when below 1e-6 (d the scattered direction as the code returns it); wi is d made a
# unit vector. No pdf: the course's materials have none. material_eval is BRDF(view, light)
# with the view ray coming along -wo and the light ray along wi, 0 where n . wi < 1e-6 (as the
# integrator's cut-off makes it). The course's Lambertian, Phong, Blinn and CookTorrance only;
# other types are declined.

import random as _random

MATERIAL_OPS = ("material_sample", "material_eval")
MATERIAL_TYPES = ("lambertian", "phong", "blinn", "cook_torrance")

_FUNCTION_OPS = OPS
_function_answer = answer
OPS = tuple(_FUNCTION_OPS) + MATERIAL_OPS


class _RowNumbers:
    """random_double for one sample: the row's numbers, then a generator seeded by the row."""

    def __init__(self):
        self.row = []
        self.next_index = 0
        self.more = None

    def start(self, row):
        self.row = [float(x) for x in row]
        self.next_index = 0
        self.more = None

    def __call__(self, min=0.0, max=1.0):
        if self.next_index < len(self.row):
            u = self.row[self.next_index]
            self.next_index += 1
        else:
            if self.more is None:
                self.more = _random.Random(repr(self.row))
            u = self.more.random()
        return min + u * (max - min)


class _PatchedRandom:
    """Replaces random_double in every module of the submission that holds it, for a block."""

    def __init__(self, source):
        self.source = source
        self.undo = []

    def __enter__(self):
        util = module("RT_utility")
        original = getattr(util, "random_double", None)
        for _, m in modules():
            value = getattr(m, "random_double", None)
            if value is not None and (value is original or m is util):
                self.undo.append((m, value))
                setattr(m, "random_double", self.source)
        return self

    def __exit__(self, *exc):
        for m, value in reversed(self.undo):
            setattr(m, "random_double", value)
        return False


def _setup(req):
    spec = req["material"]
    if spec.get("type") not in MATERIAL_TYPES:
        return None
    m = make_material(spec)
    wo = [float(x) for x in req["wo"]]
    view = make_ray({"origin": wo, "direction": [-wo[0], -wo[1], -wo[2]]})
    hit = make_hit({"point": [0.0, 0.0, 0.0], "normal": req["normal"], "t": 1.0}, view, m)
    return m, view, hit


def _colour(value, what):
    if isinstance(value, (int, float)) or type(value).__name__.startswith("float"):
        x = out_num(value, what)
        return [x, x, x]
    return out_vec(value, what)


def _declined(req):
    return {"declined": "the course adapter checks the course's lambertian, phong, blinn and "
                        "cook_torrance, not %r" % (req["material"].get("type"),)}


def op_material_sample(req):
    setup = _setup(req)
    if setup is None:
        return _declined(req)
    m, view, hit = setup
    n = [float(x) for x in req["normal"]]
    what = type(m).__name__
    brdf = method(m, "BRDF", what)
    numbers = _RowNumbers()
    samples = []
    rows = req["u"]
    with Seeded(int(float(rows[0][0]) * 2**31) if rows else 0), _PatchedRandom(numbers):
        for row in rows:
            numbers.start(row)
            s = method(m, "scattering", what)(view, hit)
            if s is None:
                samples.append(None)
                continue
            ray = getattr(s, "scattered_ray", None)
            if ray is None:
                raise BadReturn("%s.scattering returned no scattered_ray" % what)
            d = [num_in(x) for x in out_vec(ray.getDirection(), what + "'s direction")]
            c = d[0] * n[0] + d[1] * n[1] + d[2] * n[2]
            if c < 1e-6:
                c = 0.0
            f = _colour(brdf(view, ray, hit), what + ".BRDF")
            length = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
            wi = [x / length for x in d] if length > 0 else d
            samples.append({"wi": [number(x) for x in wi],
                            "weight": [number(num_in(x) * c) for x in f]})
    return {"samples": samples}


def op_material_eval(req):
    setup = _setup(req)
    if setup is None:
        return _declined(req)
    m, view, hit = setup
    n = [float(x) for x in req["normal"]]
    what = type(m).__name__ + ".BRDF"
    brdf = method(m, "BRDF", type(m).__name__)
    out = []
    for wi in req["wi"]:
        w = [float(x) for x in wi]
        if w[0] * n[0] + w[1] * n[1] + w[2] * n[2] < 1e-6:
            out.append([0.0, 0.0, 0.0])
            continue
        light = make_ray({"origin": [0.0, 0.0, 0.0], "direction": w})
        out.append(_colour(brdf(view, light, hit), what))
    return {"f": out}


_MATERIAL_HANDLERS = {"material_sample": op_material_sample,
                      "material_eval": op_material_eval}


def answer(req):
    """The result object of a function or material request."""
    handler = _MATERIAL_HANDLERS.get(req.get("op"))
    if handler is not None:
        return handler(req)
    return _function_answer(req)
