"""rtoracle's adapter for the course's Python API (protocol 1, JSON lines, stdlib only).

Usage: python3 -I -B python_course.py SUBMISSION_DIR

Imports RT_utility, RT_ray and RT_object from SUBMISSION_DIR, builds the course's objects with
their constructors and answers one request line with one answer line, in order, flushing after
each answer so that a case that hangs or crashes is attributed to that case.
"""

import json
import sys
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
    e = v.e
    return "[" + num(e[0]) + "," + num(e[1]) + "," + num(e[2]) + "]"


def error_json(exc):
    tb = traceback.format_exc()
    if len(tb) > TB_LIMIT:
        tb = "..." + tb[-TB_LIMIT:]
    return json.dumps(
        {"type": type(exc).__name__, "message": str(exc)[:TB_LIMIT], "traceback": tb}
    )


def main():
    submission = sys.argv[1] if len(sys.argv) > 1 else "."
    sys.path.insert(0, submission)
    stdin = sys.stdin.buffer
    out = sys.stdout
    loads = json.loads

    first = stdin.readline()
    if not first:
        return
    hello = {"name": "python-course " + submission, "protocol": 1, "shapes": ["sphere", "quad"]}
    try:
        import RT_utility
        import RT_ray
        import RT_object
    except BaseException as exc:  # SyntaxError, ImportError, SystemExit, ...
        hello["error"] = loads(error_json(exc))
        out.write(json.dumps(hello) + "\n")
        out.flush()
        # Keep answering so every case gets the import error.
        for line in stdin:
            try:
                rid = json.dumps(loads(line).get("id"))
            except Exception:
                rid = "null"
            out.write('{"id":' + rid + ',"error":' + json.dumps(hello["error"]) + "}\n")
            out.flush()
        return

    Vec3 = RT_utility.Vec3
    Interval = RT_utility.Interval
    Ray = RT_ray.Ray
    Sphere = getattr(RT_object, "Sphere", None)
    Quad = getattr(RT_object, "Quad", None)
    Triangle = getattr(RT_object, "Triangle", None)
    # The week-4 Triangle is an empty stub: support it only when it takes three vertices.
    try:
        Triangle(Vec3(0.0, 0.0, 0.0), Vec3(1.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0)).intersect
        hello["shapes"].append("triangle")
    except BaseException:
        pass
    out.write(json.dumps(hello) + "\n")
    out.flush()

    def v3(a):
        return Vec3(float(a[0]), float(a[1]), float(a[2]))

    for line in stdin:
        rid = "null"
        try:
            req = loads(line)
            rid = json.dumps(req["id"])
            s = req["shape"]
            kind = s["type"]
            if kind == "sphere":
                obj = Sphere(v3(s["center"]), float(s["radius"]), None)
            elif kind == "quad":
                obj = Quad(v3(s["q"]), v3(s["u"]), v3(s["v"]), None)
            else:
                obj = Triangle(v3(s["a"]), v3(s["b"]), v3(s["c"]))
            r = req["ray"]
            iv = req["interval"]
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
                    + ',"front_face":' + ("true" if hit.front_face else "false")
                    + "}\n"
                )
        except BaseException as exc:  # anything the submission raises, SystemExit included
            ans = '{"id":' + rid + ',"error":' + error_json(exc) + "}\n"
        out.write(ans)
        out.flush()


main()
