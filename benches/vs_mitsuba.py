"""rtoracle's reference renderer against Mitsuba 3 on the scenes both share (issue 43, item 6).

For each scene, exported by `rtoracle scenes --export mitsuba NAME --profile physical`, it times
Mitsuba's render (scalar_rgb, and llvm_ad_rgb when Dr.Jit finds a libLLVM: Debian's libllvm19
and DRJIT_LIBLLVM_PATH) and `rtoracle render NAME --profile physical` at the same size and spp,
on one thread (CPU time) and on all (wall clock), and prints samples per second and the ratio.
Each side keeps its best of --runs runs, the sides taking turns. The scene's loading, Mitsuba's
JIT compilation (its first render) and rtoracle's start-up are outside Mitsuba's times and inside
rtoracle's (a whole process), which favours Mitsuba slightly.

usage: python3 benches/vs_mitsuba.py [--rtoracle PATH] [--spp N] [--runs K] [SCENE...]
"""
import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time

import drjit as dr
import mitsuba as mi

parser = argparse.ArgumentParser()
parser.add_argument("--rtoracle", default="target/release/rtoracle")
parser.add_argument("--spp", type=int, default=64)
parser.add_argument("--runs", type=int, default=3)
parser.add_argument("scenes", nargs="*", default=["week05-quad", "week05-quad-light"])
args = parser.parse_args()
cores = os.cpu_count() or 1


def child_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def rtoracle(name, threads, out):
    env = dict(os.environ)
    if threads:
        env["RAYON_NUM_THREADS"] = str(threads)
    cpu, wall = child_cpu(), time.perf_counter()
    subprocess.run(
        [args.rtoracle, "render", name, "--profile", "physical", "--spp", str(args.spp), "-o", out],
        check=True, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return child_cpu() - cpu, time.perf_counter() - wall


def mitsuba(scene, threads):
    dr.set_thread_count(threads)
    cpu, wall = time.process_time(), time.perf_counter()
    image = mi.render(scene, spp=args.spp, seed=1)
    dr.eval(image)
    dr.sync_thread()  # the LLVM variant runs its kernels asynchronously
    return time.process_time() - cpu, time.perf_counter() - wall


variants = ["scalar_rgb"]
# The LLVM variant only with the libLLVM named: Dr.Jit finds an older one by itself (Debian 12's
# LLVM 14 or 15), which cannot compile its kernels and aborts the process.
if os.environ.get("DRJIT_LIBLLVM_PATH"):
    variants.append("llvm_ad_rgb")
else:
    print("llvm_ad_rgb: not measured (set DRJIT_LIBLLVM_PATH to Debian's libllvm19, "
          "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1)")

print(f"rtoracle against Mitsuba {mi.__version__}: {args.spp} spp, best of {args.runs} runs, {cores} cores")
print(f"  {'scene':<18} {'variant':<12} {'one core (CPU time)':>36}   {'all cores (wall clock)':>36}")
with tempfile.TemporaryDirectory() as tmp:
    for name in args.scenes:
        xml = subprocess.run(
            [args.rtoracle, "scenes", "--export", "mitsuba", name, "--profile", "physical"],
            check=True, capture_output=True, text=True).stdout
        path = os.path.join(tmp, name + ".xml")
        with open(path, "w") as f:
            f.write(xml)
        out = os.path.join(tmp, name + ".exr")
        for variant in variants:
            mi.set_variant(variant)
            scene = mi.load_file(path)
            w, h = scene.sensors()[0].film().size()
            samples = w * h * args.spp
            mitsuba(scene, 1)  # warm-up (the LLVM variant compiles its kernels here)
            best = {"r1": 1e9, "m1": 1e9, "ra": 1e9, "ma": 1e9}
            for _ in range(args.runs):
                best["r1"] = min(best["r1"], rtoracle(name, 1, out)[0])
                best["m1"] = min(best["m1"], mitsuba(scene, 1)[0])
                best["ra"] = min(best["ra"], rtoracle(name, None, out)[1])
                best["ma"] = min(best["ma"], mitsuba(scene, cores)[1])
            rate = {k: samples / v / 1e6 for k, v in best.items()}
            print(f"  {name:<18} {variant:<12} rtoracle {rate['r1']:6.2f}M/s Mitsuba {rate['m1']:6.2f}M/s "
                  f"{rate['r1'] / rate['m1']:5.2f}x   rtoracle {rate['ra']:6.2f}M/s Mitsuba {rate['ma']:6.2f}M/s "
                  f"{rate['ra'] / rate['ma']:5.2f}x")
sys.stdout.flush()
