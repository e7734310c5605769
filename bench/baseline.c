/*
 * The baseline of `rtoracle bench render`: a plain C loop doing the same work as rtoracle's
 * reference tracer on the course's two week-4 scenes.
 *
 * Same scenes, same camera (the course's, after Ray Tracing in One Weekend), same per-pixel random
 * streams (PCG-XSL-RR 128/64 seeded from the seed and the pixel index, as rtoracle's
 * PixelSampler), the same uniform jitter, the same closest-hit loop over the objects in order with
 * the interval (1e-6, closest so far), the same robust sphere roots (Ray Tracing Gems ch. 7), the
 * same quad test, the same sky, the same mean (the sum over the count, or the common value when
 * every sample saw the same colour), and every floating-point operation in the same order. So it
 * renders the same film bit for bit, which the benchmark checks through the checksum it prints.
 *
 * Build: cc -O3 -ffp-contract=off -o baseline baseline.c -lm
 * Run:   ./baseline REPS        (prints, per scene: name width height best_seconds checksum)
 *
 * Written for rtoracle (MIT licence); the scene data are the course's.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct {
    double x, y, z;
} vec3;

static inline vec3 v3(double x, double y, double z) {
    vec3 r = {x, y, z};
    return r;
}
static inline vec3 add(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3 sub(vec3 a, vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vec3 mul(vec3 a, double s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline vec3 divs(vec3 a, double s) { return v3(a.x / s, a.y / s, a.z / s); }
static inline double dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 cross(vec3 a, vec3 b) {
    return v3(a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y);
}
static inline vec3 unit(vec3 a) { return divs(a, sqrt(dot(a, a))); }

/* ---- random numbers: PCG-XSL-RR 128/64, one stream per pixel ---- */

typedef unsigned __int128 u128;

typedef struct {
    u128 state, inc;
} pcg;

static const u128 PCG_MUL = ((u128)0x2360ED051FC65DA4ull << 64) | 0x4385DF649FCCF645ull;

static inline uint64_t mix(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static inline pcg pixel_stream(uint64_t seed, uint64_t pixel) {
    pcg p;
    u128 state = ((u128)mix(seed) << 64) | mix(pixel ^ 0x9e3779b97f4a7c15ull);
    u128 stream = ((u128)pixel << 64) | seed;
    p.inc = (stream << 1) | 1;
    p.state = state + p.inc;
    p.state = p.state * PCG_MUL + p.inc;
    return p;
}

static inline double next_f64(pcg *p) {
    p->state = p->state * PCG_MUL + p->inc;
    unsigned rot = (unsigned)(p->state >> 122);
    uint64_t xsl = (uint64_t)(p->state >> 64) ^ (uint64_t)p->state;
    uint64_t r = (xsl >> rot) | (xsl << ((64 - rot) & 63));
    return (double)(r >> 11) * (1.0 / 9007199254740992.0);
}

/* ---- objects: a sphere or a quad, intersected in list order ---- */

enum { SPHERE, QUAD };

typedef struct {
    int kind;
    vec3 albedo;
    vec3 center; /* sphere */
    double radius;
    vec3 q, u, v, normal, w; /* quad */
    double d;
} object;

static object sphere(vec3 c, double r, vec3 albedo) {
    object o = {0};
    o.kind = SPHERE;
    o.center = c;
    o.radius = r;
    o.albedo = albedo;
    return o;
}

static object quad(vec3 q, vec3 u, vec3 v, vec3 albedo) {
    object o = {0};
    vec3 n = cross(u, v);
    o.kind = QUAD;
    o.q = q;
    o.u = u;
    o.v = v;
    o.normal = unit(n);
    o.d = dot(o.normal, q);
    o.w = divs(n, dot(n, n));
    o.albedo = albedo;
    return o;
}

/* The t of the hit in (tmin, tmax) (open), or NAN for a miss. */
static inline double hit_sphere(const object *s, vec3 o, vec3 d, double tmin, double tmax) {
    vec3 f = sub(o, s->center);
    double a = dot(d, d);
    double half_b = dot(f, d);
    double r2 = s->radius * s->radius;
    vec3 perp = sub(f, mul(d, half_b / a));
    double disc = a * (r2 - dot(perp, perp));
    if (!(disc >= 0.0)) return NAN;
    double c = dot(f, f) - r2;
    double q = -(half_b + copysign(sqrt(disc), half_b));
    double t0, t1;
    if (q == 0.0) {
        t0 = t1 = -half_b / a;
    } else {
        t0 = c / q;
        t1 = q / a;
        if (!(t0 <= t1)) {
            double t = t0;
            t0 = t1;
            t1 = t;
        }
    }
    if (tmin < t0 && t0 < tmax) return t0;
    if (tmin < t1 && t1 < tmax) return t1;
    return NAN;
}

/* The t of the hit in [tmin, tmax] (closed), or NAN for a miss. */
static inline double hit_quad(const object *s, vec3 o, vec3 d, double tmin, double tmax) {
    double denom = dot(s->normal, d);
    if (!(fabs(denom) >= 1e-8)) return NAN;
    double t = (s->d - dot(s->normal, o)) / denom;
    if (!(tmin <= t && t <= tmax)) return NAN;
    vec3 p = sub(add(o, mul(d, t)), s->q);
    double alpha = dot(s->w, cross(p, s->v));
    double beta = dot(s->w, cross(s->u, p));
    if (0.0 <= alpha && alpha <= 1.0 && 0.0 <= beta && beta <= 1.0) return t;
    return NAN;
}

static inline vec3 radiance(const object *objs, int n, vec3 o, vec3 d) {
    int best = -1;
    double closest = DBL_MAX;
    for (int k = 0; k < n; k++) {
        double t = objs[k].kind == SPHERE ? hit_sphere(&objs[k], o, d, 1e-6, closest)
                                          : hit_quad(&objs[k], o, d, 1e-6, closest);
        if (t == t) {
            closest = t;
            best = k;
        }
    }
    if (best >= 0) return objs[best].albedo;
    double a = 0.5 * (unit(d).y + 1.0);
    return v3((1.0 - a) * 1.0 + a * 0.5, (1.0 - a) * 1.0 + a * 0.7, (1.0 - a) * 1.0 + a * 1.0);
}

/* ---- the course's camera ---- */

typedef struct {
    int width, height;
    vec3 center, pixel00, du, dv;
} camera;

static camera make_camera(int width, double aspect, vec3 from, vec3 at) {
    camera c;
    vec3 up = v3(0.0, 1.0, 0.0);
    double vfov = 90.0, focus = 10.0;
    int height = (int)(width / aspect);
    c.width = width;
    c.height = height < 1 ? 1 : height;
    c.center = from;
    double theta = vfov * M_PI / 180.0;
    double h = tan(theta / 2.0);
    double vh = 2.0 * h * focus;
    double vw = vh * ((double)c.width / (double)c.height);
    vec3 w = unit(sub(from, at));
    vec3 u = unit(cross(up, w));
    vec3 v = cross(w, u);
    vec3 vu = mul(u, vw);
    vec3 vv = mul(v3(-v.x, -v.y, -v.z), vh);
    c.du = divs(vu, (double)c.width);
    c.dv = divs(vv, (double)c.height);
    vec3 upper_left = sub(sub(sub(from, mul(w, focus)), divs(vu, 2.0)), divs(vv, 2.0));
    c.pixel00 = add(upper_left, mul(add(c.du, c.dv), 0.5));
    return c;
}

/* ---- rendering: the mean of spp jittered samples per pixel, row-major ---- */

static void render(const camera *cam, const object *objs, int n, int spp, uint64_t seed,
                   vec3 *film) {
    for (int j = 0; j < cam->height; j++) {
        for (int i = 0; i < cam->width; i++) {
            uint64_t pixel = (uint64_t)j * (uint64_t)cam->width + (uint64_t)i;
            pcg rng = pixel_stream(seed, pixel);
            vec3 sum = v3(0.0, 0.0, 0.0), first = sum;
            int uniform = 1;
            for (int s = 0; s < spp; s++) {
                double ox = next_f64(&rng) - 0.5;
                double oy = next_f64(&rng) - 0.5;
                vec3 sample = add(add(cam->pixel00, mul(cam->du, (double)i + ox)),
                                  mul(cam->dv, (double)j + oy));
                vec3 d = sub(sample, cam->center);
                vec3 colour = radiance(objs, n, cam->center, d);
                sum = add(sum, colour);
                if (s == 0)
                    first = colour;
                else
                    uniform &= colour.x == first.x && colour.y == first.y && colour.z == first.z;
            }
            /* All samples equal: that colour exactly (a sum over the count can be an ulp off). */
            film[pixel] = uniform ? first : divs(sum, (double)spp);
        }
    }
}

/* FNV-1a over the bits of every channel of every pixel: rtoracle computes the same. */
static uint64_t checksum(const vec3 *film, size_t n) {
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t k = 0; k < n; k++) {
        double c[3] = {film[k].x, film[k].y, film[k].z};
        for (int ch = 0; ch < 3; ch++) {
            uint64_t bits;
            memcpy(&bits, &c[ch], sizeof bits);
            for (int b = 0; b < 8; b++) {
                h ^= (bits >> (8 * b)) & 0xff;
                h *= 0x100000001b3ull;
            }
        }
    }
    return h;
}

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void run(const char *name, camera cam, const object *objs, int n, int reps) {
    size_t pixels = (size_t)cam.width * (size_t)cam.height;
    vec3 *film = malloc(pixels * sizeof *film);
    if (!film) {
        fprintf(stderr, "baseline: out of memory\n");
        exit(2);
    }
    double best = 1e300;
    for (int r = 0; r < reps; r++) {
        double t = now();
        render(&cam, objs, n, 20, 0, film);
        t = now() - t;
        if (t < best) best = t;
    }
    printf("%s %d %d %.6f %016llx\n", name, cam.width, cam.height, best,
           (unsigned long long)checksum(film, pixels));
    free(film);
}

int main(int argc, char **argv) {
    int reps = argc > 1 ? atoi(argv[1]) : 3;
    if (reps < 1) reps = 1;

    object spheres[] = {
        sphere(v3(0.0, -100.5, -1.0), 100.0, v3(0.0, 0.0, 0.8)),
        sphere(v3(0.0, 0.0, -1.0), 0.5, v3(0.8, 0.8, 0.0)),
        sphere(v3(-1.0, 0.0, -1.0), 0.5, v3(0.8, 0.0, 0.0)),
        sphere(v3(-1.0, 0.0, -1.0), -0.4, v3(0.8, 0.8, 0.0)),
        sphere(v3(1.0, 0.0, -1.0), 0.5, v3(0.8, 0.0, 0.0)),
    };
    object quads[] = {
        quad(v3(-3, -2, 5), v3(0, 0, -4), v3(0, 4, 0), v3(1.0, 0.2, 0.2)),
        quad(v3(-2, -2, 0), v3(4, 0, 0), v3(0, 4, 0), v3(0.2, 1.0, 0.2)),
        quad(v3(3, -2, 1), v3(0, 0, 4), v3(0, 4, 0), v3(0.2, 0.2, 1.0)),
        quad(v3(-2, 3, 1), v3(4, 0, 0), v3(0, 0, 4), v3(1.0, 0.5, 0.0)),
        quad(v3(-2, -3, 5), v3(4, 0, 0), v3(0, 0, -4), v3(0.2, 0.8, 0.8)),
    };
    run("week04-sphere", make_camera(400, 16.0 / 9.0, v3(0, 0, 1), v3(0, 0, -1)), spheres, 5,
        reps);
    run("week04-quad", make_camera(400, 1.0, v3(0, 0, 10), v3(0, 0, 0)), quads, 5, reps);
    return 0;
}
