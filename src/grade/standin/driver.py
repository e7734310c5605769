# rtoracle grade: STAND-IN driver (to be replaced by the `check` module's adapter).
# Stdlib only. Imports the course's modules from the current folder, then answers one JSON
# line per request: {"id", "shape", "ray", "interval"} -> {"id", "hit", "t", "point", "normal",
# "front_face"} or {"id", "error": {...}}. Numbers that are not finite travel as "inf"/"-inf"/"nan".
import json, math, os, sys, traceback

out = os.fdopen(os.dup(1), "w")
os.dup2(2, 1)          # anything the student prints goes to stderr, never into the answers
sys.stdout = sys.stderr
requests = os.fdopen(os.dup(0), "r")
os.dup2(os.open(os.devnull, os.O_RDONLY), 0)   # and input() cannot eat the requests
sys.stdin = open(os.devnull)
sys.path.insert(0, os.getcwd())


def send(obj):
    out.write(json.dumps(obj, allow_nan=False) + "\n")
    out.flush()


def num(x):
    if isinstance(x, str):
        return float(x.replace("+", ""))
    return float(x)


def enc(x):
    x = float(x)
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return x


def vec_out(v):
    e = getattr(v, "e", None)
    if e is None:
        e = [v.x(), v.y(), v.z()]
    return [enc(c) for c in list(e)[:3]]


try:
    import RT_utility as rtu
    import RT_ray as rtr
    import RT_object as rto
except BaseException as exc:
    # Name the file by its base name only: the sandbox's folder means nothing to the student.
    if isinstance(exc, SyntaxError):
        where = "%s, line %s" % (os.path.basename(exc.filename or "?"), exc.lineno)
        text = (exc.text or "").rstrip()
        msg = "%s: %s (%s)" % (type(exc).__name__, exc.msg, where)
        if text:
            msg += "\n    " + text.strip()
    else:
        frames = [f for f in traceback.extract_tb(exc.__traceback__)
                  if os.path.basename(f.filename) != os.path.basename(__file__)]
        msg = "%s: %s" % (type(exc).__name__, exc)
        if frames:
            f = frames[-1]
            msg += " (%s, line %s)" % (os.path.basename(f.filename), f.lineno)
            if f.line:
                msg += "\n    " + f.line.strip()
    send({"fatal": msg})
    sys.exit(0)
send({"ready": True})


def vec(a):
    return rtu.Vec3(num(a[0]), num(a[1]), num(a[2]))


for line in requests:
    if not line.strip():
        continue
    req = json.loads(line)
    cid = req["id"]
    try:
        s = req["shape"]
        if s["type"] == "sphere":
            obj = rto.Sphere(vec(s["center"]), num(s["radius"]))
        elif s["type"] == "quad":
            obj = rto.Quad(vec(s["q"]), vec(s["u"]), vec(s["v"]))
        else:
            raise NotImplementedError("shape " + s["type"])
        ray = rtr.Ray(vec(req["ray"]["origin"]), vec(req["ray"]["direction"]))
        interval = rtu.Interval(num(req["interval"][0]), num(req["interval"][1]))
        h = obj.intersect(ray, interval)
        if h is None or h is False:
            ans = {"id": cid, "hit": False}
        else:
            ans = {"id": cid, "hit": True, "t": enc(h.getT()), "point": vec_out(h.getP()),
                   "normal": vec_out(h.getNormal()), "front_face": bool(h.front_face)}
    except Exception as exc:
        ans = {"id": cid, "error": {"type": type(exc).__name__, "message": str(exc),
                                    "traceback": "".join(traceback.format_exc().splitlines(True)[-4:])}}
    send(ans)
