"""Times Mitsuba 3's renders for `rtoracle bench render` (embedded in the binary and run as
`python3 -c`). It reads one command a line on stdin and answers one line on stdout:

  load VARIANT SPP PATH   load the scene file at PATH in VARIANT (scalar_rgb, llvm_ad_rgb) and
                          render it once at SPP on one thread, untimed (the LLVM variant compiles
                          its kernels there): "ok WIDTH HEIGHT VERSION"
  time THREADS            render the loaded scene at its SPP on THREADS threads:
                          "time CPU_SECONDS WALL_SECONDS" (the process's CPU time, the wall clock)

and "error WHY" when a command fails. Only trusted input reaches it: the scenes rtoracle exported.
"""
import sys
import time

try:
    import drjit as dr
    import mitsuba as mi
except Exception as e:  # noqa: BLE001 - the reason is reported, whatever it is
    print("error cannot import mitsuba:", str(e).replace("\n", " "), flush=True)
    sys.exit(0)

scene, spp = None, 1


def render(threads):
    dr.set_thread_count(threads)
    image = mi.render(scene, spp=spp, seed=1)
    dr.eval(image)
    dr.sync_thread()  # the LLVM variant runs its kernels asynchronously


print("ready", mi.__version__, flush=True)
for line in sys.stdin:
    words = line.split(maxsplit=3)
    try:
        if words[0] == "load":
            mi.set_variant(words[1])
            spp = int(words[2])
            scene = mi.load_file(words[3].rstrip("\n"))
            w, h = scene.sensors()[0].film().size()
            render(1)
            print("ok", w, h, flush=True)
        elif words[0] == "time":
            cpu, wall = time.process_time(), time.perf_counter()
            render(int(words[1]))
            print("time", time.process_time() - cpu, time.perf_counter() - wall, flush=True)
        else:
            print("error unknown command", words[0], flush=True)
    except Exception as e:  # noqa: BLE001 - the reason is reported, whatever it is
        print("error", str(e).replace("\n", " "), flush=True)
