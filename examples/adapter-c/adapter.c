/*
 * A complete rtoracle adapter in C, written from docs/PROTOCOL.md alone: spheres, quads and
 * triangles, the way a Ray Tracing in One Weekend style renderer intersects them, in double
 * precision. It passes `rtoracle check` under both profiles (course and robust).
 *
 * Build: cc -O2 -o adapter adapter.c -lm
 * Run:   rtoracle check --adapter ./adapter --profile robust
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

int main(void) {
    static char line[1 << 16];
    while (fgets(line, sizeof line, stdin)) {
        if (field_is(line, "op", "hello")) {
            printf("{\"name\":\"c-adapter\",\"protocol\":1,"
                   "\"shapes\":[\"sphere\",\"quad\",\"triangle\"]}\n");
        } else if (!answer(line)) {
            continue;
        }
        fflush(stdout);
    }
    return 0;
}
