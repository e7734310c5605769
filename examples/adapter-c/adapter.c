/*
 * A complete rtoracle adapter in C, written from docs/PROTOCOL.md alone: spheres, quads and
 * triangles, the way a Ray Tracing in One Weekend style renderer intersects them, in double
 * precision. It passes `rtoracle check` under both profiles (course and robust).
 *
 * Build: cc -O2 -o adapter adapter.c -lm
 * Run:   rtoracle check --adapter ./adapter --profile robust
 *
 * It also answers the material requests (the book's lambertian, metal and dielectric; see
 * "Materials" below), which `rtoracle physics --adapter ./adapter` checks, and renders spheres of
 * those materials (see "Renders" below), which `rtoracle physics --furnace --adapter ./adapter`
 * checks against scenes whose answer is known.
 *
 * Build with -DOPEN_EDGES to see the classic open-edge mistake (`alpha > 0` where `alpha >= 0`
 * is meant, and `disc > 0` for spheres): one shape alone cannot show it, but the suite's
 * watertight groups (two shapes sharing an edge) do.
 *
 * - Spheres: the discriminant and roots after Ray Tracing Gems ch. 7 (the naive
 *   `half_b^2 - a c` loses far and scaled spheres, which `--profile robust` scores); the near
 *   root if the open interval contains it, else the far root.
 * - Quads: RTIOW's `Q + alpha u + beta v` with `w = n / (n . n)`, closed edges, closed
 *   interval, `|unit(n) . d| < 1e-8` is parallel.
 * - Triangles: the same plane test with the third edge `alpha + beta <= 1` (the normal is
 *   `unit((b - a) x (c - a))`).
 *
 * The parser is small but relies on nothing the protocol does not promise: it finds each field
 * by its key ("key", optional whitespace, a colon) in any order, and reads numbers with strtod,
 * which understands "inf", "-inf" and "nan" once the quote is skipped. Numbers are printed with
 * %.17g (enough to read back the same double), non-finite ones as the strings. Every answer is
 * flushed: simple, and a crash or a hang is then blamed on the right case.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef OPEN_EDGES
#define INSIDE(x) ((x) > 0 && (x) < 1)
#define DISC_OK(x) ((x) > 0)
#else
#define INSIDE(x) ((x) >= 0 && (x) <= 1)
#define DISC_OK(x) ((x) >= 0)
#endif

static const char *skip_space(const char *p) {
    while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n') p++;
    return p;
}

/* The value of the field named key (just after its colon and any whitespace), or NULL. */
static const char *field(const char *s, const char *key) {
    char quoted[64];
    snprintf(quoted, sizeof quoted, "\"%s\"", key);
    for (const char *p = strstr(s, quoted); p; p = strstr(p + 1, quoted)) {
        const char *q = skip_space(p + strlen(quoted));
        if (*q == ':') return skip_space(q + 1);
    }
    return NULL;
}

/* Whether the field named key is the JSON string value. */
static int field_is(const char *s, const char *key, const char *value) {
    const char *p = field(s, key);
    size_t n = strlen(value);
    return p && *p == '"' && strncmp(p + 1, value, n) == 0 && p[1 + n] == '"';
}

/* Reads n numbers of a JSON array starting at p (just after the key). */
static int numbers(const char *p, double *out, int n) {
    if (!p) return 0;
    p = skip_space(p);
    if (*p != '[') return 0;
    p++;
    for (int i = 0; i < n; i++) {
        while (*p == ' ' || *p == '\t' || *p == ',' || *p == '"') p++;
        char *end;
        out[i] = strtod(p, &end);
        if (end == p) return 0;
        p = end;
    }
    return 1;
}

static double number(const char *p) {
    if (!p) return NAN;
    if (*p == '"') p++;
    return strtod(p, NULL);
}

static void put(double x) {
    if (isnan(x)) printf("\"nan\"");
    else if (isinf(x)) printf(x > 0 ? "\"inf\"" : "\"-inf\"");
    else printf("%.17g", x);
}

static void put3(const double *v) {
    printf("[");
    put(v[0]); printf(",");
    put(v[1]); printf(",");
    put(v[2]); printf("]");
}

static double dot(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross(const double *a, const double *b, double *out) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static void sub(const double *a, const double *b, double *out) {
    for (int k = 0; k < 3; k++) out[k] = a[k] - b[k];
}

/* A hit: t and the outward normal (not yet facing the ray). */
struct hit { double t, outward[3]; };

static int sphere(const double *c, double r, const double *o, const double *d, const double *iv,
                  struct hit *h) {
    double f[3];
    sub(o, c, f);
    double a = dot(d, d), half_b = dot(f, d), cc = dot(f, f) - r * r;
    /* r^2 - |f - (f . d / a) d|^2, times a: the robust discriminant. */
    double k = half_b / a, perp[3];
    for (int i = 0; i < 3; i++) perp[i] = f[i] - k * d[i];
    double disc = a * (r * r - dot(perp, perp));
    if (!DISC_OK(disc)) return 0;
    double q = -(half_b + copysign(sqrt(disc), half_b));
    double t0 = q == 0 ? -half_b / a : cc / q, t1 = q == 0 ? -half_b / a : q / a;
    double near = fmin(t0, t1), far = fmax(t0, t1);
    double t;
    if (iv[0] < near && near < iv[1]) t = near;
    else if (iv[0] < far && far < iv[1]) t = far;
    else return 0;
    h->t = t;
    for (int i = 0; i < 3; i++) h->outward[i] = (o[i] + t * d[i] - c[i]) / r;
    return 1;
}

/* The plane of Q + alpha u + beta v; with triangle, alpha + beta <= 1 too. */
static int plane(const double *q, const double *u, const double *v, int triangle,
                 const double *o, const double *d, const double *iv, struct hit *h) {
    double n[3];
    cross(u, v, n);
    double nn = dot(n, n), len = sqrt(nn);
    if (!(len > 0)) return 0;
    double normal[3] = {n[0] / len, n[1] / len, n[2] / len};
    double w[3] = {n[0] / nn, n[1] / nn, n[2] / nn};
    double denom = dot(normal, d);
    if (!(fabs(denom) >= 1e-8)) return 0;
    double t = (dot(normal, q) - dot(normal, o)) / denom;
    if (!isfinite(t) || !(iv[0] <= t && t <= iv[1])) return 0;
    double p[3], pxv[3], uxp[3];
    for (int i = 0; i < 3; i++) p[i] = o[i] + t * d[i] - q[i];
    cross(p, v, pxv);
    cross(u, p, uxp);
    double alpha = dot(w, pxv), beta = dot(w, uxp);
    if (triangle) {
        if (!(INSIDE(alpha) && INSIDE(beta) && INSIDE(alpha + beta))) return 0;
    } else if (!(INSIDE(alpha) && INSIDE(beta))) {
        return 0;
    }
    h->t = t;
    for (int i = 0; i < 3; i++) h->outward[i] = normal[i];
    return 1;
}

/* Answers one request line; 0 when the line has no id. */
static int answer(const char *line) {
    const char *id = field(line, "id");
    if (!id || *id != '"') return 0;
    const char *id_end = id + 1;
    while (*id_end && *id_end != '"') id_end += (*id_end == '\\' && id_end[1]) ? 2 : 1;
    if (*id_end != '"') return 0;
    int id_len = (int)(id_end - id + 1);

    double o[3], d[3], iv[2], a[3], b[3], c[3];
    struct hit h;
    int ok = numbers(field(line, "origin"), o, 3) && numbers(field(line, "direction"), d, 3) &&
             numbers(field(line, "interval"), iv, 2);
    int hit = 0;
    if (ok && field_is(line, "type", "sphere") && numbers(field(line, "center"), a, 3)) {
        hit = sphere(a, number(field(line, "radius")), o, d, iv, &h);
    } else if (ok && field_is(line, "type", "quad") && numbers(field(line, "q"), a, 3) &&
               numbers(field(line, "u"), b, 3) && numbers(field(line, "v"), c, 3)) {
        hit = plane(a, b, c, 0, o, d, iv, &h);
    } else if (ok && field_is(line, "type", "triangle") && numbers(field(line, "a"), a, 3) &&
               numbers(field(line, "b"), b, 3) && numbers(field(line, "c"), c, 3)) {
        double u[3], v[3];
        sub(b, a, u);
        sub(c, a, v);
        hit = plane(a, u, v, 1, o, d, iv, &h);
    } else {
        printf("{\"id\":%.*s,\"error\":{\"type\":\"BadRequest\",\"message\":\"unknown request\"}}\n",
               id_len, id);
        return 1;
    }
    if (!hit) {
        printf("{\"id\":%.*s,\"hit\":false}\n", id_len, id);
        return 1;
    }
    double p[3], n[3];
    for (int k = 0; k < 3; k++) p[k] = o[k] + h.t * d[k];
    int front = dot(d, h.outward) < 0;
    for (int k = 0; k < 3; k++) n[k] = front ? h.outward[k] : -h.outward[k];
    printf("{\"id\":%.*s,\"hit\":true,\"t\":", id_len, id);
    put(h.t);
    printf(",\"point\":");
    put3(p);
    printf(",\"normal\":");
    put3(n);
    printf(",\"front_face\":%s}\n", front ? "true" : "false");
    return 1;
}

/* ------------------------------------------------------------------------------------------
 * Materials (docs/PROTOCOL.md, "Material requests"): the book's lambertian, metal (fuzz) and
 * dielectric, with their exact pdfs. wo and wi point away from the surface; n is the outward
 * normal. Each sample gets four uniform numbers u from the grader: a unit vector is
 * (z = 1 - 2 u0, phi = 2 pi u1), the dielectric's choice is u0.
 *
 * Build with one of -DMISTAKE_PDF_NO_COSINE, -DMISTAKE_UNIFORM_HEMISPHERE,
 * -DMISTAKE_WEIGHT_NOT_DIVIDED, -DMISTAKE_NO_TIR, -DMISTAKE_ENERGY_GAIN or
 * -DMISTAKE_NON_RECIPROCAL to see what `rtoracle physics` says about each catalogued mistake.
 * ------------------------------------------------------------------------------------------ */
#define PI 3.14159265358979323846

struct material { int kind; double albedo[3], fuzz, ior; }; /* kind 0 lambertian, 1 metal, 2 dielectric */

/* Reads the material object at mat (a request's "material", or a scene's material entry). */
static int material_at(const char *mat, struct material *m) {
    if (!mat) return 0;
    m->albedo[0] = m->albedo[1] = m->albedo[2] = 1.0;
    numbers(field(mat, "albedo"), m->albedo, 3);
    m->fuzz = 0;
    m->ior = 1.5;
    if (field_is(mat, "type", "lambertian")) m->kind = 0;
    else if (field_is(mat, "type", "metal")) {
        m->kind = 1;
        m->fuzz = number(field(mat, "roughness"));
        if (!(m->fuzz >= 0)) return 0;
        if (m->fuzz > 1) m->fuzz = 1;
    } else if (field_is(mat, "type", "dielectric")) {
        m->kind = 2;
        m->ior = number(field(mat, "ior"));
        if (!(m->ior > 0)) return 0;
    } else return 0;
    return 1;
}

static int read_material(const char *line, struct material *m) {
    return material_at(field(line, "material"), m);
}

static void sphere_point(double u0, double u1, double *out) {
    double z = 1 - 2 * u0, r = sqrt(fmax(0, 1 - z * z)), phi = 2 * PI * u1;
    out[0] = r * cos(phi);
    out[1] = r * sin(phi);
    out[2] = z;
}

static void normalize(double *v) {
    double l = sqrt(dot(v, v));
    for (int k = 0; k < 3; k++) v[k] /= l;
}

static void reflect_about(const double *v, const double *n, double *out) {
    double d = dot(v, n);
    for (int k = 0; k < 3; k++) out[k] = v[k] - 2 * d * n[k];
}

static double schlick(double cosine, double ratio) {
    double r0 = (1 - ratio) / (1 + ratio);
    r0 = r0 * r0;
    return r0 + (1 - r0) * pow(1 - cosine, 5);
}

/* The density of unit(r + f s), s uniform on the unit sphere, at the unit direction d. */
static double fuzz_pdf(const double *r, const double *d, double f) {
    double c = fmax(-1, fmin(1, dot(r, d))), g = f * f - (1 - c * c);
    if (c <= 0 || g <= 0) return 0;
    double sq = sqrt(g), far = c + sq, near = fmax(0, c - sq);
    return (far * far + near * near) / (4 * PI * f * sq);
}

/* f(wo, wi) and the pdf of wi; 0 for the dielectric (a delta). */
static void bsdf(const struct material *m, const double *wo, const double *n, const double *wi,
                 double *f, double *pdf) {
    double c = dot(wi, n), r[3], mwo[3] = {-wo[0], -wo[1], -wo[2]};
    f[0] = f[1] = f[2] = 0;
    *pdf = 0;
    if (c <= 0 || m->kind == 2) return;
    if (m->kind == 1) {
        if (m->fuzz == 0) return;
        reflect_about(mwo, n, r);
        *pdf = fuzz_pdf(r, wi, m->fuzz);
        for (int k = 0; k < 3; k++) f[k] = m->albedo[k] * *pdf / c;
        return;
    }
#if defined(MISTAKE_ENERGY_GAIN)
    for (int k = 0; k < 3; k++) f[k] = m->albedo[k];
#elif defined(MISTAKE_NON_RECIPROCAL)
    for (int k = 0; k < 3; k++) f[k] = m->albedo[k] * (1 - schlick(c, 1.5)) / PI;
#else
    for (int k = 0; k < 3; k++) f[k] = m->albedo[k] / PI;
#endif
#ifdef MISTAKE_PDF_NO_COSINE
    *pdf = 1 / PI;
#else
    *pdf = c / PI;
#endif
}

static void put_sample(const double *wi, const double *w, double pdf, int delta) {
    printf("{\"wi\":");
    put3(wi);
    printf(",\"weight\":");
    put3(w);
    printf(",\"pdf\":");
    put(pdf);
    printf(delta ? ",\"delta\":true}" : "}");
}

/* One sample with the numbers u; 0 when absorbed. */
static int sample(const struct material *m, const double *wo, const double *n, const double *u,
                  double *wi, double *weight, double *pdf, int *delta) {
    double mwo[3] = {-wo[0], -wo[1], -wo[2]}, s[3], f[3];
    *delta = 0;
    if (m->kind == 0) {
        sphere_point(u[0], u[1], s);
#ifdef MISTAKE_UNIFORM_HEMISPHERE
        double sign = dot(s, n) < 0 ? -1 : 1;
        for (int k = 0; k < 3; k++) wi[k] = sign * s[k];
#else
        for (int k = 0; k < 3; k++) wi[k] = n[k] + s[k];
        if (dot(wi, wi) < 1e-16) for (int k = 0; k < 3; k++) wi[k] = n[k];
        normalize(wi);
#endif
        bsdf(m, wo, n, wi, f, pdf);
        double c = fabs(dot(wi, n));
#ifdef MISTAKE_WEIGHT_NOT_DIVIDED
        for (int k = 0; k < 3; k++) weight[k] = f[k] * c;
#else
        for (int k = 0; k < 3; k++) weight[k] = f[k] * c / *pdf;
#endif
        return 1;
    }
    if (m->kind == 1) {
        double r[3];
        reflect_about(mwo, n, r);
        if (m->fuzz == 0) {
            if (dot(r, n) <= 0) return 0;
            for (int k = 0; k < 3; k++) { wi[k] = r[k]; weight[k] = m->albedo[k]; }
            *pdf = 1;
            *delta = 1;
            return 1;
        }
        sphere_point(u[0], u[1], s);
        for (int k = 0; k < 3; k++) wi[k] = r[k] + m->fuzz * s[k];
        normalize(wi);
        if (dot(wi, n) <= 0) return 0;
        for (int k = 0; k < 3; k++) weight[k] = m->albedo[k];
        *pdf = fuzz_pdf(r, wi, m->fuzz);
        return 1;
    }
    /* The book's dielectric: Schlick's reflectance, total internal reflection. */
    int outside = dot(wo, n) > 0;
    double facing[3], ratio = outside ? 1 / m->ior : m->ior;
    for (int k = 0; k < 3; k++) facing[k] = outside ? n[k] : -n[k];
    double cosine = fmin(dot(wo, facing), 1), sine = sqrt(1 - cosine * cosine);
    double reflectance = schlick(cosine, ratio);
#ifdef MISTAKE_NO_TIR
    int cannot = 0;
    (void)sine;
#else
    int cannot = ratio * sine > 1;
#endif
    *delta = 1;
    for (int k = 0; k < 3; k++) weight[k] = m->albedo[k];
    if (cannot || reflectance > u[0]) {
        reflect_about(mwo, facing, wi);
        *pdf = cannot ? 1 : reflectance;
        return 1;
    }
    double perp[3];
    for (int k = 0; k < 3; k++) perp[k] = ratio * (mwo[k] + cosine * facing[k]);
    double par = -sqrt(fabs(1 - dot(perp, perp)));
    for (int k = 0; k < 3; k++) wi[k] = perp[k] + par * facing[k];
    *pdf = 1 - reflectance;
    return 1;
}

/* Calls row(values) for each row of width numbers in the JSON array of arrays at p. */
static int each_row(const char *p, int width, void (*row)(const double *, void *), void *ctx) {
    if (!p || *p != '[') return 0;
    p = skip_space(p + 1);
    while (*p == '[') {
        double v[4];
        if (!numbers(p, v, width)) return 0;
        row(v, ctx);
        p = strchr(p, ']');
        if (!p) return 0;
        p = skip_space(p + 1);
        if (*p == ',') p = skip_space(p + 1);
    }
    return *p == ']';
}

struct material_call { const struct material *m; double wo[3], n[3]; int first, eval; };

static void sample_row(const double *u, void *ctx) {
    struct material_call *c = ctx;
    double wi[3], w[3], pdf;
    int delta;
    printf(c->first ? "" : ",");
    c->first = 0;
    if (sample(c->m, c->wo, c->n, u, wi, w, &pdf, &delta)) put_sample(wi, w, pdf, delta);
    else printf("null");
}

static void eval_row(const double *wi, void *ctx) {
    struct material_call *c = ctx;
    double f[3], pdf;
    printf(c->first ? "" : ",");
    c->first = 0;
    bsdf(c->m, c->wo, c->n, wi, f, &pdf);
    if (c->eval) put3(f);
    else put(pdf);
}

/* Answers a material request; 0 when the line is not one. */
static int answer_material(const char *line, const char *id, int id_len) {
    const char *list;
    int op;
    if (field_is(line, "op", "material_sample")) { op = 0; list = field(line, "u"); }
    else if (field_is(line, "op", "material_eval")) { op = 1; list = field(line, "wi"); }
    else if (field_is(line, "op", "material_pdf")) { op = 2; list = field(line, "wi"); }
    else return 0;
    struct material m;
    struct material_call c = {&m, {0}, {0}, 1, op == 1};
    if (!read_material(line, &m)) {
        printf("{\"id\":%.*s,\"result\":{\"declined\":\"this adapter has the book's lambertian, "
               "metal and dielectric only\"}}\n", id_len, id);
        return 1;
    }
    if (!numbers(field(line, "wo"), c.wo, 3) || !numbers(field(line, "normal"), c.n, 3)) {
        printf("{\"id\":%.*s,\"error\":{\"type\":\"BadRequest\",\"message\":\"no wo or normal\"}}\n",
               id_len, id);
        return 1;
    }
    static const char *keys[] = {"samples", "f", "pdf"};
    printf("{\"id\":%.*s,\"result\":{\"%s\":[", id_len, id, keys[op]);
    int ok = each_row(list, op == 0 ? 4 : 3, op == 0 ? sample_row : eval_row, &c);
    printf("]}}\n");
    if (!ok) fprintf(stderr, "adapter: a malformed list in %.60s\n", line);
    return 1;
}

/* ------------------------------------------------------------------------------------------
 * Renders (docs/PROTOCOL.md, "Render requests"): spheres of the book's three materials under
 * the scene's flat background or the book's sky, seen through the scene file's pinhole camera,
 * by the book's path tracer: at each hit the direction and weight of sample() above, at most
 * max_depth hits, the background times the throughput on a miss. Enough for
 * `rtoracle physics --furnace --adapter ./adapter`, whose scenes have a closed-form answer.
 * ------------------------------------------------------------------------------------------ */
#define MAX_OBJECTS 64

struct named { char name[64]; struct material m; };
struct ball { double c[3], r; int mat; };
struct scene {
    struct named mats[MAX_OBJECTS];
    struct ball balls[MAX_OBJECTS];
    int nmats, nballs, sky, depth, width, height;
    double env[3], from[3], at[3], up[3], vfov;
};

/* Just past the JSON object or array starting at p (strings skipped), or NULL. */
static const char *value_end(const char *p) {
    int depth = 0, in_string = 0;
    for (; *p; p++) {
        if (in_string) {
            if (*p == '\\' && p[1]) p++;
            else if (*p == '"') in_string = 0;
        } else if (*p == '"') in_string = 1;
        else if (*p == '{' || *p == '[') depth++;
        else if ((*p == '}' || *p == ']') && --depth == 0) return p + 1;
    }
    return NULL;
}

/* The string value at p (after its key) copied into out; 0 when it is not a short string. */
static int string_at(const char *p, char *out, size_t size) {
    if (!p || *p != '"') return 0;
    const char *end = strchr(p + 1, '"');
    if (!end || (size_t)(end - p - 1) >= size) return 0;
    memcpy(out, p + 1, (size_t)(end - p - 1));
    out[end - p - 1] = 0;
    return 1;
}

/* Calls each(object, scene) for every object of the JSON array at p, each copied alone. */
static int each_object(const char *p, int (*each)(const char *, struct scene *), struct scene *s) {
    static char one[8192];
    if (!p || *p != '[') return 0;
    p = skip_space(p + 1);
    while (*p == '{') {
        const char *end = value_end(p);
        if (!end || (size_t)(end - p) >= sizeof one) return 0;
        memcpy(one, p, (size_t)(end - p));
        one[end - p] = 0;
        if (!each(one, s)) return 0;
        p = skip_space(end);
        if (*p == ',') p = skip_space(p + 1);
    }
    return *p == ']';
}

static int add_material(const char *o, struct scene *s) {
    if (s->nmats == MAX_OBJECTS) return 0;
    struct named *n = &s->mats[s->nmats];
    if (!string_at(field(o, "name"), n->name, sizeof n->name) || !material_at(o, &n->m)) return 0;
    s->nmats++;
    return 1;
}

static int add_sphere(const char *o, struct scene *s) {
    char name[64];
    const char *moving = field(o, "moving_center");
    if (s->nballs == MAX_OBJECTS || !field_is(o, "type", "sphere") || (moving && *moving != 'n'))
        return 0;
    struct ball *b = &s->balls[s->nballs];
    if (!numbers(field(o, "center"), b->c, 3) || !string_at(field(o, "material"), name, sizeof name))
        return 0;
    b->r = number(field(o, "radius"));
    b->mat = -1;
    for (int i = 0; i < s->nmats; i++)
        if (strcmp(s->mats[i].name, name) == 0) b->mat = i;
    if (b->mat < 0 || !(b->r > 0)) return 0;
    s->nballs++;
    return 1;
}

/* Reads the request's scene; 0 when it has something this adapter does not render. */
static int read_scene(const char *line, struct scene *s) {
    const char *sc = field(line, "scene"), *render = sc ? field(sc, "render") : NULL;
    memset(s, 0, sizeof *s);
    if (!sc || field(sc, "textures") || !field_is(sc, "profile", "physical")) return 0;
    const char *image = field(sc, "image"), *camera = field(sc, "camera");
    s->width = (int)number(field(image, "width"));
    s->height = (int)(s->width / number(field(image, "aspect_ratio")));
    if (s->height < 1) s->height = 1;
    if (!numbers(field(camera, "look_from"), s->from, 3) || !numbers(field(camera, "look_at"), s->at, 3) ||
        !numbers(field(camera, "up"), s->up, 3) || number(field(camera, "defocus_angle")) != 0)
        return 0;
    s->vfov = number(field(camera, "vfov"));
    s->depth = render && field(render, "max_depth") ? (int)number(field(render, "max_depth")) : 50;
    s->sky = !(render && field_is(render, "background", "flat"));
    s->env[0] = s->env[1] = s->env[2] = 0.01;
    if (render) numbers(field(render, "background_color"), s->env, 3);
    return each_object(field(sc, "materials"), add_material, s) &&
           each_object(field(sc, "objects"), add_sphere, s);
}

/* SplitMix64: a pixel's own stream of numbers in [0, 1). */
static double next_random(unsigned long long *state) {
    unsigned long long z = (*state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return (double)((z ^ (z >> 31)) >> 11) / 9007199254740992.0;
}

/* The radiance along the ray o + t d. */
static void radiance(const struct scene *s, const double *o0, const double *d0,
                     unsigned long long *rng, double *out) {
    double o[3], d[3], throughput[3] = {1, 1, 1};
    memcpy(o, o0, sizeof o);
    memcpy(d, d0, sizeof d);
    for (int bounce = 0; bounce < s->depth; bounce++) {
        double best = INFINITY, iv[2] = {0.001, INFINITY};
        const struct ball *hit = NULL;
        for (int i = 0; i < s->nballs; i++) {
            struct hit h;
            iv[1] = best;
            if (sphere(s->balls[i].c, s->balls[i].r, o, d, iv, &h)) {
                best = h.t;
                hit = &s->balls[i];
            }
        }
        if (!hit) {
            double a = 0.5 * (d[1] / sqrt(dot(d, d)) + 1), sky[3] = {1 - 0.5 * a, 1 - 0.3 * a, 1};
            for (int k = 0; k < 3; k++) out[k] = throughput[k] * (s->sky ? sky[k] : s->env[k]);
            return;
        }
        double p[3], outward[3], wo[3], u[2], wi[3], weight[3], pdf;
        int delta;
        for (int k = 0; k < 3; k++) {
            p[k] = o[k] + best * d[k];
            outward[k] = (p[k] - hit->c[k]) / hit->r;
            wo[k] = -d[k];
        }
        normalize(wo);
        /* The dielectric tells inside from outside by the outward normal; the others scatter
         * about the normal that faces the ray. */
        if (s->mats[hit->mat].m.kind != 2 && dot(wo, outward) < 0)
            for (int k = 0; k < 3; k++) outward[k] = -outward[k];
        u[0] = next_random(rng);
        u[1] = next_random(rng);
        if (!sample(&s->mats[hit->mat].m, wo, outward, u, wi, weight, &pdf, &delta)) break;
        for (int k = 0; k < 3; k++) {
            throughput[k] *= weight[k];
            o[k] = p[k];
            d[k] = wi[k];
        }
    }
    out[0] = out[1] = out[2] = 0;
}

/* Answers a render request; 0 when the line is not one. */
static int answer_render(const char *line, const char *id, int id_len) {
    static struct scene s;
    double tile[4];
    if (!field_is(line, "op", "render")) return 0;
    if (!read_scene(line, &s) || !numbers(field(line, "tile"), tile, 4)) {
        printf("{\"id\":%.*s,\"result\":{\"declined\":\"this adapter renders spheres of the book's "
               "materials in the physical profile only\"}}\n", id_len, id);
        return 1;
    }
    int spp = (int)number(field(line, "spp"));
    unsigned long long seed = (unsigned long long)number(field(line, "seed"));
    double w[3], u[3], v[3], h = tan(s.vfov * PI / 360), aspect = (double)s.width / s.height;
    sub(s.from, s.at, w);
    normalize(w);
    cross(s.up, w, u);
    normalize(u);
    cross(w, u, v);
    printf("{\"id\":%.*s,\"result\":{\"tile\":[%d,%d,%d,%d],\"rgb\":[", id_len, id,
           (int)tile[0], (int)tile[1], (int)tile[2], (int)tile[3]);
    for (int j = (int)tile[1]; j < (int)tile[3]; j++)
        for (int i = (int)tile[0]; i < (int)tile[2]; i++) {
            unsigned long long rng = seed * 0x100000001B3ULL + (unsigned long long)(j * s.width + i);
            double sum[3] = {0, 0, 0}, L[3], d[3];
            for (int n = 0; n < spp; n++) {
                double sx = (2 * (i + next_random(&rng)) / s.width - 1) * h * aspect;
                double sy = (1 - 2 * (j + next_random(&rng)) / s.height) * h;
                for (int k = 0; k < 3; k++) d[k] = sx * u[k] + sy * v[k] - w[k];
                radiance(&s, s.from, d, &rng, L);
                for (int k = 0; k < 3; k++) sum[k] += L[k];
            }
            printf(i == (int)tile[0] && j == (int)tile[1] ? "" : ",");
            printf("%.9g,%.9g,%.9g", sum[0] / spp, sum[1] / spp, sum[2] / spp);
        }
    printf("]}}\n");
    return 1;
}

/* The id of a request line (with its quotes), or NULL. */
static const char *request_id(const char *line, int *len) {
    const char *id = field(line, "id");
    if (!id || *id != '"') return NULL;
    const char *end = id + 1;
    while (*end && *end != '"') end += (*end == '\\' && end[1]) ? 2 : 1;
    if (*end != '"') return NULL;
    *len = (int)(end - id + 1);
    return id;
}

int main(void) {
    static char line[1 << 21];
    while (fgets(line, sizeof line, stdin)) {
        int id_len;
        const char *id = request_id(line, &id_len);
        if (field_is(line, "op", "hello")) {
            printf("{\"name\":\"c-adapter\",\"protocol\":1,"
                   "\"shapes\":[\"sphere\",\"quad\",\"triangle\"],"
                   "\"ops\":[\"intersect\",\"material_sample\",\"material_eval\",\"material_pdf\","
                   "\"render\"]}\n");
        } else if (id && answer_material(line, id, id_len)) {
        } else if (id && answer_render(line, id, id_len)) {
        } else if (!answer(line)) {
            continue;
        }
        fflush(stdout);
    }
    return 0;
}
