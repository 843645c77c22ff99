/*
 * A stand-in for the cosdem binaries, used ONLY to exercise the deployment plumbing
 * (FROM-scratch images, compose secrets/health checks/DNS, the fault-injection test)
 * before the real binaries exist. It follows the CLI contract's shape, not its protocol:
 * a line-based TCP exchange instead of gRPC, and a fake deterministic "solution".
 *
 *   standin listen --listen ADDR [--token-file PATH]      (token also from COSDEM_TOKEN)
 *   standin health --addr HOST:PORT                        (no token, like the real one)
 *   standin run JOB.toml [--workers LIST] --out DIR [--token-file PATH]
 *
 * LIST: comma-separated host:port or dns:NAME:PORT (every address of NAME). Each step
 * must be confirmed by one live worker (tried in turn, 1 s connect/read timeout), else
 * the run fails. Steps: "steps = N" in the job file (default 8); STANDIN_STEP_MS sets the
 * time per step (default 700). Outputs: curve.csv, vtk/step_NNNN.vtu, fields.pvd,
 * gauss.pvd, summary.json, identical with or without workers (summary.json aside).
 */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static const char *opt(int argc, char **argv, const char *name) {
    for (int i = 0; i + 1 < argc; i++)
        if (strcmp(argv[i], name) == 0) return argv[i + 1];
    return NULL;
}

static void read_token(int argc, char **argv, char *tok, size_t n) {
    const char *path = opt(argc, argv, "--token-file");
    tok[0] = 0;
    if (path) {
        FILE *f = fopen(path, "r");
        if (!f) { fprintf(stderr, "cannot read token file %s: %s\n", path, strerror(errno)); exit(2); }
        if (!fgets(tok, (int)n, f)) tok[0] = 0;
        fclose(f);
    } else if (getenv("COSDEM_TOKEN")) {
        snprintf(tok, n, "%s", getenv("COSDEM_TOKEN"));
    }
    tok[strcspn(tok, "\r\n")] = 0;
}

/* Split "HOST:PORT" at the last colon. */
static int split_hostport(const char *s, char *host, size_t hn, char *port, size_t pn) {
    const char *c = strrchr(s, ':');
    if (!c || (size_t)(c - s) >= hn) return -1;
    memcpy(host, s, (size_t)(c - s));
    host[c - s] = 0;
    snprintf(port, pn, "%s", c + 1);
    return 0;
}

static int connect_timeout(const struct sockaddr *sa, socklen_t len, int ms) {
    int fd = socket(sa->sa_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd < 0) return -1;
    if (connect(fd, sa, len) < 0 && errno != EINPROGRESS) { close(fd); return -1; }
    struct pollfd p = {fd, POLLOUT, 0};
    int err = 0;
    socklen_t el = sizeof err;
    if (poll(&p, 1, ms) != 1 || getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &el) < 0 || err) {
        close(fd);
        return -1;
    }
    fcntl(fd, F_SETFL, 0);
    struct timeval tv = {ms / 1000, (ms % 1000) * 1000};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
    return fd;
}

/* Send one request line to an address; 0 iff the reply starts with `want`. */
static int ask(const struct sockaddr *sa, socklen_t len, const char *req, const char *want) {
    int fd = connect_timeout(sa, len, 1000);
    if (fd < 0) return -1;
    char buf[64] = {0};
    int ok = write(fd, req, strlen(req)) == (ssize_t)strlen(req) && read(fd, buf, sizeof buf - 1) > 0 &&
             strncmp(buf, want, strlen(want)) == 0;
    close(fd);
    return ok ? 0 : -1;
}

static void on_term(int sig) { (void)sig; _exit(0); }

static int cmd_listen(int argc, char **argv) {
    const char *addr = opt(argc, argv, "--listen");
    char host[256], port[16], tok[256];
    if (!addr || split_hostport(addr, host, sizeof host, port, sizeof port)) {
        fprintf(stderr, "listen: --listen HOST:PORT required\n");
        return 2;
    }
    read_token(argc, argv, tok, sizeof tok);
    if (!tok[0] && strncmp(host, "127.", 4) != 0 && strcmp(host, "localhost") != 0 && strcmp(host, "::1") != 0) {
        fprintf(stderr, "listen: refusing to bind non-loopback %s without a token\n", addr);
        return 2;
    }
    signal(SIGTERM, on_term); /* as PID 1 in a container, SIGTERM needs a handler */
    signal(SIGINT, on_term);
    signal(SIGPIPE, SIG_IGN);
    struct addrinfo hints = {.ai_family = AF_UNSPEC, .ai_socktype = SOCK_STREAM, .ai_flags = AI_PASSIVE}, *res;
    if (getaddrinfo(host, port, &hints, &res) != 0) { fprintf(stderr, "listen: bad address %s\n", addr); return 2; }
    int s = socket(res->ai_family, SOCK_STREAM | SOCK_CLOEXEC, 0), one = 1;
    setsockopt(s, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (s < 0 || bind(s, res->ai_addr, res->ai_addrlen) < 0 || listen(s, 64) < 0) {
        fprintf(stderr, "listen: %s: %s\n", addr, strerror(errno));
        return 1;
    }
    freeaddrinfo(res);
    fprintf(stderr, "standin worker listening on %s\n", addr);
    char step_ok[300];
    snprintf(step_ok, sizeof step_ok, "STEP %s\n", tok);
    for (;;) {
        int c = accept4(s, NULL, NULL, SOCK_CLOEXEC);
        if (c < 0) continue;
        struct timeval tv = {1, 0};
        setsockopt(c, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
        char buf[300] = {0};
        ssize_t n = read(c, buf, sizeof buf - 1);
        const char *reply = "DENIED\n";
        if (n > 0 && strcmp(buf, "HEALTH\n") == 0) reply = "SERVING\n";
        else if (n > 0 && strcmp(buf, step_ok) == 0) reply = "OK\n";
        if (write(c, reply, strlen(reply)) < 0) { /* peer gone */ }
        close(c);
    }
}

static int cmd_health(int argc, char **argv) {
    const char *addr = opt(argc, argv, "--addr");
    char host[256], port[16];
    if (!addr || split_hostport(addr, host, sizeof host, port, sizeof port)) return 2;
    struct addrinfo hints = {.ai_socktype = SOCK_STREAM}, *res, *r;
    if (getaddrinfo(host, port, &hints, &res) != 0) return 1;
    int rc = 1;
    for (r = res; r && rc; r = r->ai_next) rc = ask(r->ai_addr, r->ai_addrlen, "HEALTH\n", "SERVING") ? 1 : 0;
    freeaddrinfo(res);
    return rc;
}

struct worker { struct sockaddr_storage sa; socklen_t len; };

static int resolve_workers(const char *list, struct worker *w, int max) {
    int n = 0;
    char *copy = strdup(list), *save = NULL;
    for (char *item = strtok_r(copy, ",", &save); item; item = strtok_r(NULL, ",", &save)) {
        char host[256], port[16];
        if (strncmp(item, "dns:", 4) == 0) item += 4;
        if (split_hostport(item, host, sizeof host, port, sizeof port)) { fprintf(stderr, "bad worker %s\n", item); exit(2); }
        struct addrinfo hints = {.ai_socktype = SOCK_STREAM}, *res, *r;
        int e = getaddrinfo(host, port, &hints, &res);
        if (e != 0) { fprintf(stderr, "cannot resolve %s: %s\n", host, gai_strerror(e)); continue; }
        for (r = res; r && n < max; r = r->ai_next) {
            memcpy(&w[n].sa, r->ai_addr, r->ai_addrlen);
            w[n++].len = r->ai_addrlen;
        }
        freeaddrinfo(res);
    }
    free(copy);
    return n;
}

static int cmd_run(int argc, char **argv) {
    if (argc < 3) { fprintf(stderr, "run: JOB.toml required\n"); return 2; }
    const char *job = argv[2], *out = opt(argc, argv, "--out"), *list = opt(argc, argv, "--workers");
    if (!out) out = "runs/standin";
    int steps = 8, step_ms = getenv("STANDIN_STEP_MS") ? atoi(getenv("STANDIN_STEP_MS")) : 700;
    FILE *jf = fopen(job, "r");
    if (!jf) { fprintf(stderr, "run: cannot read %s: %s\n", job, strerror(errno)); return 2; }
    char line[512];
    while (fgets(line, sizeof line, jf)) sscanf(line, " steps = %d", &steps);
    fclose(jf);
    char tok[256], req[300], path[4096];
    read_token(argc, argv, tok, sizeof tok);
    snprintf(req, sizeof req, "STEP %s\n", tok);
    struct worker w[64];
    int nw = 0;
    if (list && (nw = resolve_workers(list, w, 64)) == 0) { fprintf(stderr, "run: no worker resolved\n"); return 3; }
    mkdir(out, 0755);
    snprintf(path, sizeof path, "%s/vtk", out);
    mkdir(path, 0755);
    snprintf(path, sizeof path, "%s/curve.csv", out);
    FILE *curve = fopen(path, "w");
    if (!curve) { fprintf(stderr, "run: %s: %s\n", path, strerror(errno)); return 1; }
    fprintf(curve, "step,displacement,load\n");
    fflush(curve);
    for (int k = 1; k <= steps; k++) {
        struct timespec ts = {step_ms / 1000, (long)(step_ms % 1000) * 1000000L};
        nanosleep(&ts, NULL);
        if (nw) {
            int done = 0;
            for (int i = 0; i < nw && !done; i++) {
                struct worker *x = &w[(k + i) % nw];
                done = ask((struct sockaddr *)&x->sa, x->len, req, "OK") == 0;
                char ip[INET6_ADDRSTRLEN] = "?";
                getnameinfo((struct sockaddr *)&x->sa, x->len, ip, sizeof ip, NULL, 0, NI_NUMERICHOST);
                fprintf(stderr, "step %d: worker %s %s\n", k, ip, done ? "served it" : "did not answer");
            }
            if (!done) { fprintf(stderr, "run: step %d: no live worker accepted it\n", k); return 4; }
        }
        double u = 1e-3 * k, f = 1.0 / 3.0 * u / (1.0 + u);
        fprintf(curve, "%d,%.17g,%.17g\n", k, u, f);
        fflush(curve);
        snprintf(path, sizeof path, "%s/vtk/step_%04d.vtu", out, k);
        FILE *v = fopen(path, "w");
        if (!v) return 1;
        fprintf(v, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\"><!-- step %d u=%.17g --></VTKFile>\n", k, u);
        fclose(v);
        fprintf(stderr, "step %d/%d\n", k, steps);
    }
    fclose(curve);
    static const char *const pvds[] = {"fields.pvd", "gauss.pvd"};
    for (int i = 0; i < 2; i++) {
        snprintf(path, sizeof path, "%s/%s", out, pvds[i]);
        FILE *p = fopen(path, "w");
        if (!p) return 1;
        fprintf(p, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\"><Collection>\n");
        for (int k = 1; k <= steps; k++) fprintf(p, "<DataSet timestep=\"%d\" file=\"vtk/step_%04d.vtu\"/>\n", k, k);
        fprintf(p, "</Collection></VTKFile>\n");
        fclose(p);
    }
    snprintf(path, sizeof path, "%s/summary.json", out);
    FILE *s = fopen(path, "w");
    if (!s) return 1;
    fprintf(s, "{\"standin\": true, \"steps\": %d, \"worker_addresses\": %d}\n", steps, nw);
    fclose(s);
    return 0;
}

int main(int argc, char **argv) {
    const char *cmd = argc > 1 ? argv[1] : "";
    if (strcmp(cmd, "listen") == 0) return cmd_listen(argc, argv);
    if (strcmp(cmd, "health") == 0) return cmd_health(argc, argv);
    if (strcmp(cmd, "run") == 0) return cmd_run(argc, argv);
    fprintf(stderr, "usage: %s listen|health|run ... (deployment stand-in, not cosdem)\n", argv[0]);
    return 2;
}
