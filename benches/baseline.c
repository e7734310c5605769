/*
 * The baseline of `rtoracle bench render`: a plain C loop doing the same work as rtoracle's
 * reference tracer, one ray at a time, on the course's scenes of weeks 4, 6 and 8.
 *
 * rtoracle passes the scene (objects, materials, integrator settings, the camera's pixel grid)
 * as the structs below and calls `rtoracle_baseline_render`. It renders with the same per-pixel
 * random streams (PCG-XSL-RR 128/64 seeded from the seed and the pixel index, as rtoracle's
 * PixelSampler), drawn in the same order; the same uniform jitter; the same closest-hit loop over
 * the objects in order; the same robust sphere roots (Ray Tracing Gems ch. 7) and quad test; the
 * same integrators (week 4's colour of the closest hit, weeks 5 to 7's direct term with the
 * course's occlusion test, week 8's BRDF integrator), scattering (week 5's Lambertian
 * `n + random unit`, the mirror, the dielectric with Schlick), Phong and Blinn BRDFs, the course's
 * 3D checker, sky and flat backgrounds; the same mean; and every floating-point operation in the
 * same order. So it renders the same film bit for bit, which the benchmark checks.
 *
 * `pow` is the one library function on the paths of these scenes whose implementations round
 * differently: the system's (glibc's) and the one rtoracle uses (the `libm` crate, a port of
 * FreeBSD's msun, for the same bits on every platform) disagree in the last bit on about 10% of
 * the arguments week 8's Phong can meet (a base uniform in [0, 1), its exponents). rtoracle
 * therefore hands its `pow` to this loop, which calls it where the reference does: the same
 * work, the same function, through a pointer.
 *
 * Build: cc -O3 -ffp-contract=off -shared -fPIC -o libbaseline.so baseline.c -lm
 * (the benchmark builds it so, in a temporary folder, and loads it).
 *
 * Written for rtoracle (MIT licence); the scene data are the course's, passed in by rtoracle.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

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

enum { SPHERE, QUAD };

/* ---- the scene as rtoracle passes it (keep in step with src/cli/bench/baseline.rs) ---- */

enum { BL_SPHERE = 0, BL_QUAD = 1 };

/* A sphere (`a` its centre, `radius`) or a quad (`a` its corner Q, `u` and `v` its sides). */
typedef struct {
    int32_t kind;
    int32_t material;
    vec3 a;
    double radius;
    vec3 u, v;
} bl_object;

enum {
    BL_LAMBERTIAN = 0,
    BL_MIRROR = 1,
    BL_DIELECTRIC = 2,
    BL_LIGHT = 3,
    BL_PHONG = 4,
    BL_BLINN = 5,
    BL_CHECKER = 6 /* a Lambertian whose colour is the course's 3D checker */
};

/* `colour`: the albedo, a light's emission, or the checker's even colour. */
typedef struct {
    int32_t kind;
    int32_t unused;
    vec3 colour;
    vec3 odd;
    double scale, ior, kd, ks, alpha;
} bl_material;

enum { BL_ALBEDO = 0, BL_DIRECT = 1, BL_BRDF = 2 };

typedef struct {
    const bl_object *objects;
    int32_t n_objects;
    int32_t n_materials;
    const bl_material *materials;
    int32_t integrator;
    int32_t max_depth;
    int32_t sky; /* else the flat `background` */
    int32_t width;
    int32_t height;
    int32_t unused;
    vec3 background;
    vec3 center, pixel00, du, dv;
    double (*pow)(double, double);
} bl_scene;

/* ---- objects: prepared once, intersected in list order ---- */

typedef struct {
    int kind;
    const bl_material *m;
    vec3 center; /* sphere */
    double radius;
    vec3 q, u, v, normal, w; /* quad */
    double d;
} object;

typedef struct {
    const object *objs;
    int n;
    const bl_scene *in;
    int lights[64];
    int n_lights;
} world;

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

static inline double hit(const object *s, vec3 o, vec3 d, double tmin, double tmax) {
    return s->kind == SPHERE ? hit_sphere(s, o, d, tmin, tmax) : hit_quad(s, o, d, tmin, tmax);
}

/* The closest hit in (1e-6, DBL_MAX): its index (or -1) and t. */
static inline int closest(const world *w, vec3 o, vec3 d, double *t_hit) {
    int best = -1;
    double closest = DBL_MAX;
    for (int k = 0; k < w->n; k++) {
        double t = hit(&w->objs[k], o, d, 1e-6, closest);
        if (t == t) {
            closest = t;
            best = k;
        }
    }
    *t_hit = closest;
    return best;
}

/* The course's occlusion test: more than one object hit by p + t (c - p) on (1e-6, |c - p|). */
static inline int occluded(const world *w, vec3 p, vec3 c) {
    vec3 d = sub(c, p);
    double reach = sqrt(dot(d, d));
    int count = 0;
    for (int k = 0; k < w->n && count < 2; k++) {
        double t = hit(&w->objs[k], p, d, 1e-6, reach);
        if (t == t) count++;
    }
    return count > 1;
}

/* ---- surfaces, textures, scattering, BRDFs ---- */

typedef struct {
    vec3 point, normal;
    int front;
} surface;

static inline surface surface_of(const object *s, vec3 o, vec3 d, double t) {
    surface h;
    h.point = add(o, mul(d, t));
    vec3 outward = s->kind == SPHERE ? divs(sub(h.point, s->center), s->radius) : s->normal;
    h.front = dot(d, outward) < 0.0;
    h.normal = h.front ? outward : v3(-outward.x, -outward.y, -outward.z);
    return h;
}

/* The material's colour at p: its albedo, or the checker's (course: floor(p * (1 / scale)) summed). */
static inline vec3 colour_at(const bl_material *m, vec3 p) {
    if (m->kind != BL_CHECKER) return m->colour;
    double inv = 1.0 / m->scale;
    double cells = floor(p.x * inv) + floor(p.y * inv) + floor(p.z * inv);
    double r = fmod(cells, 2.0);
    if (r < 0.0) r += 2.0;
    return r == 0.0 ? m->colour : m->odd;
}

static inline vec3 random_unit(pcg *rng) {
    for (;;) {
        double x = -1.0 + 2.0 * next_f64(rng);
        double y = -1.0 + 2.0 * next_f64(rng);
        double z = -1.0 + 2.0 * next_f64(rng);
        vec3 p = v3(x, y, z);
        double l2 = dot(p, p);
        if (1e-160 < l2 && l2 <= 1.0) return divs(p, sqrt(l2));
    }
}

static inline vec3 reflect(vec3 v, vec3 n) { return sub(v, mul(n, 2.0 * dot(v, n))); }

static inline double schlick(double cosine, double x) {
    double r0 = (1.0 - x) / (1.0 + x);
    r0 = r0 * r0;
    double m = 1.0 - cosine;
    double m2 = m * m;
    return r0 + (1.0 - r0) * (m2 * m2 * m);
}

/* The course's scattered direction (weeks 5 and 6); `absorbed` for a light. */
static inline int scatter(const bl_material *m, vec3 d, const surface *h, pcg *rng, vec3 *out) {
    vec3 n = h->normal;
    switch (m->kind) {
    case BL_LIGHT:
        return 0;
    case BL_MIRROR:
        *out = reflect(d, n);
        return 1;
    case BL_DIELECTRIC: {
        double ratio = h->front ? 1.0 / m->ior : m->ior;
        vec3 v = unit(d);
        double cos = fmin(-dot(v, n), 1.0);
        double sin = sqrt(1.0 - cos * cos);
        if (ratio * sin > 1.0 || schlick(cos, ratio) > next_f64(rng)) {
            *out = reflect(v, n);
        } else {
            vec3 perp = mul(add(v, mul(n, cos)), ratio);
            vec3 par = mul(n, -sqrt(fabs(1.0 - dot(perp, perp))));
            *out = add(perp, par);
        }
        return 1;
    }
    default: { /* Lambertian, checker, Phong, Blinn: n + random unit, n when that is ~0 */
        vec3 s = add(n, random_unit(rng));
        *out = fabs(s.x) < 1e-8 && fabs(s.y) < 1e-8 && fabs(s.z) < 1e-8 ? n : s;
        return 1;
    }
    }
}

/* Week 8's BRDF(view, light) at h: Phong's, Blinn's, or the colour of the others. */
static inline vec3 brdf(const bl_scene *in, const bl_material *m, vec3 view, vec3 light,
                        const surface *h) {
    vec3 n = h->normal;
    double c;
    if (m->kind == BL_PHONG) {
        vec3 r = unit(reflect(v3(-light.x, -light.y, -light.z), n));
        vec3 v = unit(v3(-view.x, -view.y, -view.z));
        c = fmax(dot(r, v), 0.0);
    } else if (m->kind == BL_BLINN) {
        vec3 half = divs(add(v3(-view.x, -view.y, -view.z), light), 2.0);
        c = fmax(dot(unit(half), n), 0.0);
    } else {
        return colour_at(m, h->point);
    }
    double p = in->pow(c, m->alpha);
    vec3 a = m->colour;
    return v3(m->kd * a.x / M_PI + m->ks * a.x * p, m->kd * a.y / M_PI + m->ks * a.y * p,
              m->kd * a.z / M_PI + m->ks * a.z * p);
}

static inline double cutoff(double x) { return x < 1e-6 ? 0.0 : x; }

static inline vec3 vmul(vec3 a, vec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }

static inline vec3 background(const bl_scene *in, vec3 d) {
    if (!in->sky) return in->background;
    double a = 0.5 * (d.y / sqrt(dot(d, d)) + 1.0);
    return v3((1.0 - a) * 1.0 + a * 0.5, (1.0 - a) * 1.0 + a * 0.7, (1.0 - a) * 1.0 + a * 1.0);
}

/* ---- the integrators ---- */

/* Week 4: the colour of the closest hit, the background on a miss. */
static inline vec3 albedo(const world *w, vec3 o, vec3 d) {
    double t;
    int k = closest(w, o, d, &t);
    if (k < 0) return background(w->in, d);
    const object *s = &w->objs[k];
    if (s->m->kind != BL_CHECKER) return s->m->colour;
    surface h = surface_of(s, o, d, t);
    return colour_at(s->m, h.point);
}

/*
 * Weeks 5 to 10's path: at each hit in (1e-6, DBL_MAX), a light returns its emission, a miss the
 * background; otherwise weeks 5 to 7 add `Le a` (`Le` the unoccluded lights' `E min(1, 1/d)`)
 * and weigh what comes back by `a`, week 8 adds `sum BRDF(d, c - P) E c(n . (c - P))` and weighs
 * what comes back by `BRDF(d, w) c(n . w)`.
 */
static inline vec3 path(const world *w, vec3 o, vec3 d, pcg *rng) {
    vec3 total = v3(0.0, 0.0, 0.0), weight = v3(1.0, 1.0, 1.0);
    for (int depth = 0; depth < w->in->max_depth; depth++) {
        double t;
        int k = closest(w, o, d, &t);
        if (k < 0) return add(total, vmul(weight, background(w->in, d)));
        const object *s = &w->objs[k];
        surface h = surface_of(s, o, d, t);
        vec3 next;
        if (!scatter(s->m, d, &h, rng, &next)) return add(total, vmul(weight, s->m->colour));
        vec3 le = v3(0.0, 0.0, 0.0);
        if (w->in->integrator == BL_DIRECT) {
            vec3 a = colour_at(s->m, h.point);
            for (int l = 0; l < w->n_lights; l++) {
                const object *light = &w->objs[w->lights[l]];
                vec3 to = sub(light->center, h.point);
                double dist = sqrt(dot(to, to));
                if (dist == 0.0 || occluded(w, h.point, light->center)) continue;
                le = add(le, mul(light->m->colour, fmin(1.0, 1.0 / dist)));
            }
            total = add(total, vmul(weight, vmul(le, a)));
            weight = vmul(weight, a);
        } else {
            vec3 n = h.normal;
            for (int l = 0; l < w->n_lights; l++) {
                const object *light = &w->objs[w->lights[l]];
                vec3 to = sub(light->center, h.point);
                if (occluded(w, h.point, light->center)) continue;
                vec3 f = brdf(w->in, s->m, d, to, &h);
                le = add(le, mul(vmul(f, light->m->colour), cutoff(dot(n, to))));
            }
            total = add(total, vmul(weight, le));
            weight = vmul(weight, mul(brdf(w->in, s->m, d, next, &h), cutoff(dot(n, next))));
        }
        if (weight.x == 0.0 && weight.y == 0.0 && weight.z == 0.0) break;
        o = h.point;
        d = next;
    }
    return total;
}

/* ---- rendering: the mean of spp jittered samples per pixel, row-major ---- */

static void render(const world *w, uint32_t spp, uint64_t seed, double *film) {
    const bl_scene *in = w->in;
    for (int j = 0; j < in->height; j++) {
        for (int i = 0; i < in->width; i++) {
            uint64_t pixel = (uint64_t)j * (uint64_t)in->width + (uint64_t)i;
            pcg rng = pixel_stream(seed, pixel);
            vec3 sum = v3(0.0, 0.0, 0.0), first = sum;
            int uniform = 1;
            for (uint32_t s = 0; s < spp; s++) {
                double ox = next_f64(&rng) - 0.5;
                double oy = next_f64(&rng) - 0.5;
                vec3 sample =
                    add(add(in->pixel00, mul(in->du, (double)i + ox)), mul(in->dv, (double)j + oy));
                vec3 d = sub(sample, in->center);
                vec3 colour;
                if (in->integrator == BL_ALBEDO)
                    colour = albedo(w, in->center, d);
                else
                    colour = path(w, in->center, d, &rng);
                sum = add(sum, colour);
                if (s == 0)
                    first = colour;
                else
                    uniform &= colour.x == first.x && colour.y == first.y && colour.z == first.z;
            }
            /* All samples equal: that colour exactly (a sum over the count can be an ulp off). */
            vec3 mean = uniform ? first : divs(sum, (double)spp);
            film[3 * pixel] = mean.x;
            film[3 * pixel + 1] = mean.y;
            film[3 * pixel + 2] = mean.z;
        }
    }
}

/*
 * Renders `in` at `spp` samples per pixel with `seed` into `film` (width x height x 3 doubles,
 * row-major). Returns 0, or 1 when the scene is not one this loop renders (an unknown kind, a
 * material out of range, more than 64 lights, no pixel), or 2 when out of memory.
 */
int rtoracle_baseline_render(const bl_scene *in, uint32_t spp, uint64_t seed, double *film) {
    if (in->width < 1 || in->height < 1 || in->n_objects < 0 || spp < 1 || !in->pow) return 1;
    if (in->integrator < BL_ALBEDO || in->integrator > BL_BRDF) return 1;
    object *objs = malloc(((size_t)in->n_objects + 1) * sizeof *objs);
    if (!objs) return 2;
    world w = {objs, in->n_objects, in, {0}, 0};
    for (int k = 0; k < in->n_objects; k++) {
        const bl_object *b = &in->objects[k];
        object *o = &objs[k];
        memset(o, 0, sizeof *o);
        if (b->material < 0 || b->material >= in->n_materials ||
            in->materials[b->material].kind < BL_LAMBERTIAN ||
            in->materials[b->material].kind > BL_CHECKER) {
            free(objs);
            return 1;
        }
        o->m = &in->materials[b->material];
        if (b->kind == BL_SPHERE) {
            o->kind = SPHERE;
            o->center = b->a;
            o->radius = b->radius;
            if (o->m->kind == BL_LIGHT) {
                if (w.n_lights == 64) {
                    free(objs);
                    return 1;
                }
                w.lights[w.n_lights++] = k;
            }
        } else if (b->kind == BL_QUAD) {
            vec3 n = cross(b->u, b->v);
            o->kind = QUAD;
            o->q = b->a;
            o->u = b->u;
            o->v = b->v;
            o->normal = unit(n);
            o->d = dot(o->normal, b->a);
            o->w = divs(n, dot(n, n));
        } else {
            free(objs);
            return 1;
        }
    }
    render(&w, spp, seed, film);
    free(objs);
    return 0;
}
