/*
 * A minimal rtoracle adapter in C: speaks the JSON-lines protocol of docs/PROTOCOL.md for
 * spheres, with the course's semantics (near root if the open interval surrounds it, else the
 * far root; outward normal (P - C) / r, flipped to face the ray).
 *
 * Build: cc -O2 -o sphere_adapter sphere_adapter.c -lm
 * Run:   rtoracle check --adapter ./sphere_adapter --vectors spheres.jsonl
 *
 * The parser is deliberately small, but it relies on nothing the protocol does not promise:
 * it finds each field by its key ("key" then optional whitespace and a colon), in whatever order
 * the keys come and with any whitespace, and reads numbers with strtod, which understands the
 * protocol's "inf", "-inf" and "nan" strings once the quote is skipped. Numbers are printed with
 * %.17g, enough to read back the same double; non-finite ones as the strings.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *skip_space(const char *p) {
    while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n') p++;
    return p;
}

/* The value of the field named key (just after its colon and any whitespace), or NULL. The
 * keys of the requests are unique words, so the first "key" followed by a colon is the field. */
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

/* Writes a double in the protocol's syntax. */
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

int main(void) {
    static char line[1 << 16];
    while (fgets(line, sizeof line, stdin)) {
        if (field_is(line, "op", "hello")) {
            printf("{\"name\":\"c-sphere-adapter\",\"protocol\":1,\"shapes\":[\"sphere\"]}\n");
            fflush(stdout);
            continue;
        }
        /* The id: copy the JSON string as it is, escapes included. */
        const char *id = field(line, "id");
        if (!id || *id != '"') continue;
        const char *id_end = id + 1;
        while (*id_end && *id_end != '"') id_end += (*id_end == '\\' && id_end[1]) ? 2 : 1;
        if (*id_end != '"') continue;
        int id_len = (int)(id_end - id + 1);

        double c[3], o[3], d[3], iv[2];
        double r = number(field(line, "radius"));
        if (!field_is(line, "type", "sphere") || !numbers(field(line, "center"), c, 3) ||
            !numbers(field(line, "origin"), o, 3) ||
            !numbers(field(line, "direction"), d, 3) ||
            !numbers(field(line, "interval"), iv, 2)) {
            printf("{\"id\":%.*s,\"error\":{\"type\":\"Unsupported\",\"message\":\"not a sphere request\"}}\n",
                   id_len, id);
            fflush(stdout);
            continue;
        }
        double oc[3] = {o[0] - c[0], o[1] - c[1], o[2] - c[2]};
        double a = dot(d, d), half_b = dot(oc, d), cc = dot(oc, oc) - r * r;
        double disc = half_b * half_b - a * cc;
        int hit = 0;
        double t = 0;
        if (disc >= 0) {
            double sq = sqrt(disc);
            t = (-half_b - sq) / a;
            if (iv[0] < t && t < iv[1]) hit = 1;
            else {
                t = (-half_b + sq) / a;
                hit = iv[0] < t && t < iv[1];
            }
        }
        if (!hit) {
            printf("{\"id\":%.*s,\"hit\":false}\n", id_len, id);
        } else {
            double p[3], n[3];
            for (int k = 0; k < 3; k++) {
                p[k] = o[k] + t * d[k];
                n[k] = (p[k] - c[k]) / r;
            }
            int front = dot(d, n) < 0;
            if (!front)
                for (int k = 0; k < 3; k++) n[k] = -n[k];
            printf("{\"id\":%.*s,\"hit\":true,\"t\":", id_len, id);
            put(t);
            printf(",\"point\":");
            put3(p);
            printf(",\"normal\":");
            put3(n);
            printf(",\"front_face\":%s}\n", front ? "true" : "false");
        }
        /* One flush per answer: simple, and a crash or hang is blamed on the right case. */
        fflush(stdout);
    }
    return 0;
}
