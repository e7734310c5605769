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
reported as the student's ("your code imports scipy, which the grader does not provide"); a
missing required module is said to be the grader's.

The requests for the course's functions of weeks 5 to 10 (reflect, refract, the samplers, ...;
docs/PROTOCOL.md, "Function requests") are answered by rtoracle's driver, a second file written
beside this one (FUNCTIONS_FILE); the hello lists them in "ops" when it is there.
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


def missing_module_message(exc):
    """What a ModuleNotFoundError means for grading, or None to keep Python's message."""
    name = getattr(exc, "name", None)
    if not isinstance(name, str) or not name:
        return None
    top = name.split(".")[0]
    if top in REQUIRES:
        return (
            "the grader's Python lacks %s, which the assignment requires: this is the "
            "grader's problem, not the submission's (tell the instructor)" % top
        )
    own = os.path.join(SUBMISSION, top + ".py")
    if top.startswith("RT_") and not os.path.exists(own):
        return (
            "your code imports %s, which is not in your submission folder (add %s.py to it)"
            % (top, top)
        )
    return "your code imports %s, which the grader does not provide" % top


def error_json(exc):
    # Leave out the adapter's own frame: the traceback starts in the submission.
    raw = exc.__traceback__
    raw = raw.tb_next if raw else None
    tb = "".join(traceback.format_exception(type(exc), exc, raw))
    if len(tb) > TB_LIMIT:
        tb = "..." + tb[-TB_LIMIT:]
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
    if message is None:
        try:
            message = str(exc)
        except Exception:
            message = "(the exception's message cannot be printed)"
    return json.dumps(
        {"type": type(exc).__name__, "message": message[:TB_LIMIT], "traceback": tb}
    )


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
        # Keep answering so every case gets the import error.
        err = json.dumps(hello["error"])
        for line in requests:
            try:
                rid = json.dumps(loads(line).get("id"))
            except Exception:
                rid = "null"
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
