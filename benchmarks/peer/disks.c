/* disks.c: event-driven simulation of equal elastic hard disks in a periodic square box.
 *
 * A port to 2D of the design of F. Smallenburg, "Efficient event-driven simulations of hard
 * spheres", Eur. Phys. J. E 45, 22 (2022), arXiv:2201.01100 (its single-event variant):
 *  - one scheduled event per disk, the earliest of its contacts with the disks of its
 *    neighbour list and its exit from its neighbour shell, the circle of radius
 *    delta = (r_n - sigma)/2 about where the disk was when its list was built;
 *  - neighbour lists (fixed capacity, symmetric): the disks whose shell centres lie within
 *    r_n, rebuilt from a cell grid (cells at least r_n wide, 3 x 3 of them scanned) when the
 *    disk leaves its shell;
 *  - a collision counter per disk: an event records its partner's count, and a contact whose
 *    partner has collided since is stale and predicted again;
 *  - lazy positions: each disk stores its position at its own time (wrapped into the box only
 *    when its list is rebuilt, so a disk and its shell centre share one image);
 *  - a calendar queue: the events of the current time block in a binary heap, those of the
 *    next B - 1 blocks unsorted in doubly linked lists (one per block, O(1) insertion and
 *    removal), later ones in an overflow list that is filed anew every B blocks. The
 *    published code sorts the current block in an unbalanced search tree, which degenerates
 *    into a chain when many events share one time, as the first shell exits of disks of
 *    equal speeds do; the heap does not;
 *  - the clock re-based every REBASE_EVENTS_PER_DISK events per disk (every time shifted back
 *    to the present, the queue rebuilt); float64 throughout, int32 indices; the large arrays
 *    aligned to 2 MiB and offered huge pages where the system has them (madvise).
 *
 * Build: gcc -O3 -march=native -o disks disks.c -lm
 * Run:   disks [-w WARMUP] [-s SHELL] [-b BLOCK] [-z] STATE
 *   STATE  float64 values (native byte order): N, box side L, radius, N pairs (x, y),
 *          N pairs (vx, vy)
 *   -w     collisions per disk run before serving (default 10)
 *   -s     neighbour-shell diameter r_n / sigma (default 2)
 *   -b     mean events per block of the queue (default 8)
 *   -z     each answer also gives Z and the relative energy change since the start
 * After the warm-up it prints "ready"; then, for each line read on stdin (a number of
 * collisions), it runs that many disk-disk collisions and prints the rate (collisions per
 * second of CLOCK_MONOTONIC time); with -z followed by the compressibility factor over those
 * collisions, Z = 1 + sum r_ij . dp_i / (2 K t) (unit masses, K the kinetic energy in the
 * centre-of-mass frame, T = K / N), and (E - E_0) / E_0.
 */
#define _POSIX_C_SOURCE 200112L
#define _DEFAULT_SOURCE        /* glibc: MADV_HUGEPAGE */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#define SHELL_EXIT (-1)        /* partner of a shell-exit event */
#define IN_LIST (-1)           /* slot of an event not in the heap */
#define REBASE_EVENTS_PER_DISK 64
#define HUGE_PAGE (2 << 20)

typedef struct {               /* 64 bytes, one cache line */
    double x, y, vx, vy, t;    /* position at the disk's own time t, velocity */
    double cx, cy;             /* centre of its neighbour shell */
    int32_t count, nnb;        /* collisions so far, neighbours listed */
} Disk;

typedef struct {               /* the event of a disk; its time is in event_time */
    int32_t partner, partner_count;
    int32_t slot;              /* place in the heap, or IN_LIST */
    int32_t list, next, prev;  /* when listed: its bucket (n_buckets: the overflow list) and
                                * its neighbours there */
} Event;

static int32_t n, cap, cells;
static double L, half_L, sigma2, delta2, reach2, cell_rate, block_events = 8.0;
static Disk *d;
static Event *ev;
static double *event_time;
static int32_t *heap, heap_size, *nb, *bucket_head;
static int32_t *cell_head, *cell_next, *cell_prev, *cell_of;
static int64_t n_buckets, current_block, refile_block, events_to_rebase;
static double block_rate;      /* blocks per unit time */
static double now, origin;     /* clock, and the time re-based away */
static double impulse_sum;     /* sum over collisions of b = r_ij . v_ij / sigma^2 */

static void fail(const char *message)
{
    fprintf(stderr, "disks: %s\n", message);
    exit(1);
}

static void *allocate(size_t bytes)
{
    void *p;
    if (posix_memalign(&p, bytes >= HUGE_PAGE ? HUGE_PAGE : 64, bytes ? bytes : 1) != 0)
        fail("out of memory");
#ifdef MADV_HUGEPAGE
    if (bytes >= HUGE_PAGE) madvise(p, bytes, MADV_HUGEPAGE);
#endif
    return p;
}

static inline double image(double dx)
{
    if (dx > half_L) return dx - L;
    if (dx < -half_L) return dx + L;
    return dx;
}

static inline double wrap(double x)
{
    if (x >= L) x -= L;
    else if (x < 0.0) {
        x += L;
        if (x >= L) x = 0.0;   /* -tiny + L rounded up to L */
    }
    return x;
}

static inline void advance(Disk *p)
{
    double dt = now - p->t;
    p->x += p->vx * dt;
    p->y += p->vy * dt;
    p->t = now;
}

/* ---- calendar queue ---- */

static void sift_up(int32_t k)
{
    int32_t i = heap[k];
    double t = event_time[i];
    while (k > 0) {
        int32_t up = (k - 1) >> 1, above = heap[up];
        if (event_time[above] <= t) break;
        heap[k] = above;
        ev[above].slot = k;
        k = up;
    }
    heap[k] = i;
    ev[i].slot = k;
}

static void sift_down(int32_t k)
{
    int32_t i = heap[k];
    double t = event_time[i];
    for (;;) {
        int32_t child = 2 * k + 1;
        if (child >= heap_size) break;
        if (child + 1 < heap_size && event_time[heap[child + 1]] < event_time[heap[child]]) child++;
        int32_t below = heap[child];
        if (event_time[below] >= t) break;
        heap[k] = below;
        ev[below].slot = k;
        k = child;
    }
    heap[k] = i;
    ev[i].slot = k;
}

/* Restore the heap after the time of the event in slot k changed. */
static void sift(int32_t k)
{
    if (k > 0 && event_time[heap[k]] < event_time[heap[(k - 1) >> 1]]) sift_up(k);
    else sift_down(k);
}

static void list_push(int32_t i, int32_t list)
{
    Event *e = ev + i;
    int32_t first = bucket_head[list];
    e->next = first;
    e->prev = -1;
    e->list = list;
    e->slot = IN_LIST;
    if (first >= 0) ev[first].prev = i;
    bucket_head[list] = i;
}

static void queue_insert(int32_t i)
{
    double block = event_time[i] * block_rate;
    if (block < (double)(current_block + 1)) {
        int32_t k = heap_size++;
        heap[k] = i;
        sift_up(k);
    } else if (block < (double)(current_block + n_buckets))
        list_push(i, (int32_t)((int64_t)block & (n_buckets - 1)));
    else list_push(i, (int32_t)n_buckets);    /* also inf */
}

/* File the event of disk i anew after its time changed. */
static void reschedule(int32_t i)
{
    Event *e = ev + i;
    if (e->slot != IN_LIST) {
        int32_t k = e->slot;
        if (event_time[i] * block_rate < (double)(current_block + 1)) {
            sift(k);           /* still in the current block */
            return;
        }
        int32_t last = heap[--heap_size];
        if (k < heap_size) {
            heap[k] = last;
            sift(k);
        }
    } else {
        if (e->next >= 0) ev[e->next].prev = e->prev;
        if (e->prev >= 0) ev[e->prev].next = e->next;
        else bucket_head[e->list] = e->next;
    }
    queue_insert(i);
}

/* Overflow events were filed at a block k0 with blocks >= k0 + B: filing them anew every B
 * blocks, before the block refile_block is reached, puts each in its bucket in time. */
static void refile_overflow(void)
{
    int32_t i = bucket_head[n_buckets];
    bucket_head[n_buckets] = -1;
    while (i >= 0) {
        int32_t following = ev[i].next;
        queue_insert(i);
        i = following;
    }
    refile_block = current_block + n_buckets;
}

/* The heap is empty: the next non-empty block becomes the current one, its events the heap. */
static void next_block(void)
{
    int64_t k = current_block + 1;
    for (;; k++) {
        if (k == refile_block) {
            current_block = k - 1;
            refile_overflow();
        }
        if (bucket_head[k & (n_buckets - 1)] >= 0) break;
    }
    current_block = k;
    int32_t *first = bucket_head + (k & (n_buckets - 1));
    for (int32_t i = *first; i >= 0; i = ev[i].next) {
        heap[heap_size] = i;
        ev[i].slot = heap_size++;
    }
    *first = -1;
    for (int32_t s = heap_size / 2 - 1; s >= 0; s--) sift_down(s);
}

static int32_t earliest(void)
{
    while (heap_size == 0) next_block();
    return heap[0];
}

/* File every event anew, blocks block_events mean times between events wide. */
static void build_queue(void)
{
    double total = 0.0;
    int32_t finite = 0;
    for (int32_t i = 0; i < n; i++)
        if (event_time[i] < INFINITY) {
            total += event_time[i] - now;
            finite++;
        }
    double mean_delay = finite > 0 && total > 0.0 ? total / finite : 1.0;
    block_rate = n / (block_events * mean_delay);
    heap_size = 0;
    for (int64_t b = 0; b <= n_buckets; b++) bucket_head[b] = -1;
    current_block = (int64_t)(now * block_rate);
    refile_block = current_block + n_buckets;
    for (int32_t i = 0; i < n; i++) queue_insert(i);
}

static void rebase(void)
{
    for (int32_t i = 0; i < n; i++) {
        d[i].t -= now;
        event_time[i] -= now;
    }
    origin += now;
    now = 0.0;
    build_queue();
    events_to_rebase = (int64_t)REBASE_EVENTS_PER_DISK * n;
}

/* ---- predictions ---- */

static inline double shell_exit_time(const Disk *p)
{
    double dx = p->x - p->cx, dy = p->y - p->cy;
    double a = p->vx * p->vx + p->vy * p->vy;
    double c = dx * dx + dy * dy - delta2;
    if (c >= 0.0) return 0.0;  /* outside by round-off */
    if (a == 0.0) return INFINITY;
    double b = dx * p->vx + dy * p->vy;
    double s = sqrt(b * b - a * c);
    return b <= 0.0 ? (s - b) / a : -c / (b + s);
}

/* The event of disk i, which is at the current time. */
static void predict(int32_t i)
{
    const Disk *p = d + i;
    double x = p->x, y = p->y, vx = p->vx, vy = p->vy;
    double tau = shell_exit_time(p);
    int32_t best = SHELL_EXIT;
    const int32_t *list = nb + (size_t)i * cap;
    for (int32_t k = 0; k < p->nnb; k++) {
        int32_t j = list[k];
        const Disk *q = d + j;
        double dt = now - q->t;
        double rx = image(x - q->x - q->vx * dt);
        double ry = image(y - q->y - q->vy * dt);
        double wx = vx - q->vx, wy = vy - q->vy;
        double b = rx * wx + ry * wy;
        double c = rx * rx + ry * ry - sigma2;
        /* |r + w tau| = sigma, first root c / (-b + sqrt(disc)) with disc = b^2 - |w|^2 c
         * formed without cancellation; taken for every neighbour and kept, without a
         * branch, when the pair approaches, meets and comes first (0 if overlapping by
         * round-off) */
        double cross = rx * wy - ry * wx;
        double disc = (wx * wx + wy * wy) * sigma2 - cross * cross;
        double t_ij = fmax(c / (sqrt(fmax(disc, 0.0)) - b), 0.0);
        int hit = (b < 0.0) & (disc > 0.0) & (t_ij < tau);
        tau = hit ? t_ij : tau;
        best = hit ? j : best;
    }
    Event *e = ev + i;
    event_time[i] = now + tau;
    e->partner = best;
    e->partner_count = best >= 0 ? d[best].count : 0;
}

/* ---- neighbour lists ---- */

static inline int32_t cell_at(double x, double y)
{
    int32_t cx = (int32_t)(x * cell_rate), cy = (int32_t)(y * cell_rate);
    if (cx >= cells) cx = cells - 1;
    if (cy >= cells) cy = cells - 1;
    return cy * cells + cx;
}

static void cell_push(int32_t i, int32_t c)
{
    int32_t first = cell_head[c];
    cell_next[i] = first;
    cell_prev[i] = -1;
    if (first >= 0) cell_prev[first] = i;
    cell_head[c] = i;
    cell_of[i] = c;
}

static void cell_unlink(int32_t i)
{
    int32_t after = cell_next[i], before = cell_prev[i];
    if (before >= 0) cell_next[before] = after;
    else cell_head[cell_of[i]] = after;
    if (after >= 0) cell_prev[after] = before;
}

/* List in i, and i in theirs, every disk j (j > i when only_later) whose shell centre lies
 * within r_n of i's. */
static void link_neighbours(int32_t i, int only_later)
{
    Disk *p = d + i;
    int32_t *list = nb + (size_t)i * cap;
    int32_t row = cell_of[i] / cells, col = cell_of[i] - row * cells, across[3], down[3];
    for (int32_t k = 0; k < 3; k++) {  /* the columns and rows around, wrapped */
        across[k] = col + k - 1 + (col + k - 1 < 0 ? cells : col + k - 1 >= cells ? -cells : 0);
        down[k] = row + k - 1 + (row + k - 1 < 0 ? cells : row + k - 1 >= cells ? -cells : 0);
    }
    for (int32_t dy = 0; dy < 3; dy++) {
        for (int32_t dx = 0; dx < 3; dx++) {
            int32_t j = cell_head[down[dy] * cells + across[dx]];
            for (; j >= 0; j = cell_next[j]) {
                if (j == i || (only_later && j < i)) continue;
                Disk *q = d + j;
                double rx = image(p->cx - q->cx), ry = image(p->cy - q->cy);
                if (rx * rx + ry * ry < reach2) {
                    if (p->nnb == cap || q->nnb == cap) fail("a neighbour list is full");
                    list[p->nnb++] = j;
                    nb[(size_t)j * cap + q->nnb++] = i;
                }
            }
        }
    }
}

/* Disk i (at the current time) left its shell: a new shell about it, a new list. */
static void rebuild(int32_t i)
{
    Disk *p = d + i;
    const int32_t *list = nb + (size_t)i * cap;
    for (int32_t k = 0; k < p->nnb; k++) {
        int32_t j = list[k];
        int32_t *other = nb + (size_t)j * cap;
        int32_t last = --d[j].nnb;
        for (int32_t m = 0;; m++)
            if (other[m] == i) {
                other[m] = other[last];
                break;
            }
    }
    p->nnb = 0;
    p->cx = p->x = wrap(p->x);
    p->cy = p->y = wrap(p->y);
    int32_t c = cell_at(p->x, p->y);
    if (c != cell_of[i]) {
        cell_unlink(i);
        cell_push(i, c);
    }
    link_neighbours(i, 0);
}

/* ---- events ---- */

static void collide(Disk *p, Disk *q)
{
    advance(q);
    double rx = image(p->x - q->x), ry = image(p->y - q->y);
    double b = (rx * (p->vx - q->vx) + ry * (p->vy - q->vy)) / sigma2;
    p->vx -= b * rx;
    p->vy -= b * ry;
    q->vx += b * rx;
    q->vy += b * ry;
    p->count++;
    q->count++;
    impulse_sum += b;
}

static void run(int64_t collisions)
{
    int64_t done = 0;
    while (done < collisions) {
        int32_t i = earliest();
        Event *e = ev + i;
        Disk *p = d + i;
        now = event_time[i];
        advance(p);
        int32_t j = e->partner;
        if (j >= 0) {
            if (d[j].count == e->partner_count) {
                collide(p, d + j);
                done++;
                predict(j);
                reschedule(j);
            }
        } else rebuild(i);
        predict(i);
        reschedule(i);
        if (--events_to_rebase == 0) rebase();
    }
}

/* ---- set-up and serving ---- */

static double kinetic_energy(int centre_of_mass_frame)
{
    double e = 0.0, px = 0.0, py = 0.0;
    for (int32_t i = 0; i < n; i++) {
        e += 0.5 * (d[i].vx * d[i].vx + d[i].vy * d[i].vy);
        px += d[i].vx;
        py += d[i].vy;
    }
    return centre_of_mass_frame ? e - 0.5 * (px * px + py * py) / n : e;
}

static void load(const char *path, double shell)
{
    FILE *f = fopen(path, "rb");
    double head[3];
    if (!f || fread(head, sizeof(double), 3, f) != 3) fail("cannot read the state file");
    n = (int32_t)head[0];
    L = head[1];
    double sigma = 2.0 * head[2];
    if (n < 2 || head[0] != n || !(L > 0.0) || !(sigma > 0.0)) fail("bad state header");
    double *xy = malloc(4 * (size_t)n * sizeof(double));
    if (!xy) fail("out of memory");
    if (fread(xy, sizeof(double), 4 * (size_t)n, f) != 4 * (size_t)n) fail("short state file");
    fclose(f);

    double reach = shell * sigma, delta = 0.5 * (shell - 1.0) * sigma;
    half_L = 0.5 * L;
    sigma2 = sigma * sigma;
    delta2 = delta * delta;
    reach2 = reach * reach;
    cells = (int32_t)(L / reach);
    if (!(shell > 1.0) || cells < 3 || reach + 2.0 * delta >= half_L)
        fail("the shell must exceed sigma and three shells fit across the box");
    cell_rate = cells / L;
    /* capacity: non-overlapping disks within r_n + delta of a shell centre number at most
     * (3 r_n / sigma)^2; below that, the mean plus eight standard deviations and a margin */
    double mean = n * acos(-1.0) * reach2 / (L * L);
    cap = (int32_t)fmin(9.0 * shell * shell, ceil(mean + 8.0 * sqrt(mean) + 16.0));

    d = allocate((size_t)n * sizeof(Disk));
    ev = allocate((size_t)n * sizeof(Event));
    event_time = allocate((size_t)n * sizeof(double));
    heap = allocate((size_t)n * sizeof(int32_t));
    nb = allocate((size_t)n * cap * sizeof(int32_t));
    cell_head = allocate((size_t)cells * cells * sizeof(int32_t));
    cell_next = allocate((size_t)n * sizeof(int32_t));
    cell_prev = allocate((size_t)n * sizeof(int32_t));
    cell_of = allocate((size_t)n * sizeof(int32_t));
    n_buckets = 64;
    while (n_buckets < n) n_buckets *= 2;
    bucket_head = allocate((size_t)(n_buckets + 1) * sizeof(int32_t));

    memset(d, 0, (size_t)n * sizeof(Disk));
    for (int32_t c = 0; c < cells * cells; c++) cell_head[c] = -1;
    for (int32_t i = 0; i < n; i++) {
        Disk *p = d + i;
        p->cx = p->x = wrap(xy[2 * i]);
        p->cy = p->y = wrap(xy[2 * i + 1]);
        p->vx = xy[2 * (size_t)n + 2 * i];
        p->vy = xy[2 * (size_t)n + 2 * i + 1];
        cell_push(i, cell_at(p->x, p->y));
    }
    free(xy);
    for (int32_t i = 0; i < n; i++) link_neighbours(i, 1);
    now = origin = 0.0;
    for (int32_t i = 0; i < n; i++) predict(i);
    build_queue();
    events_to_rebase = (int64_t)REBASE_EVENTS_PER_DISK * n;
}

int main(int argc, char **argv)
{
    double warmup = 10.0, shell = 2.0;
    int with_z = 0, option;
    while ((option = getopt(argc, argv, "w:s:b:z")) != -1) {
        switch (option) {
        case 'w': warmup = atof(optarg); break;
        case 's': shell = atof(optarg); break;
        case 'b': block_events = atof(optarg); break;
        case 'z': with_z = 1; break;
        default: fail("usage: disks [-w WARMUP] [-s SHELL] [-b BLOCK] [-z] STATE");
        }
    }
    if (optind != argc - 1) fail("usage: disks [-w WARMUP] [-s SHELL] [-b BLOCK] [-z] STATE");
    if (!(block_events > 0.0)) fail("-b must be positive");
    load(argv[optind], shell);
    double energy0 = kinetic_energy(0);
    run((int64_t)(warmup * n));
    printf("ready\n");
    fflush(stdout);

    char line[64];
    while (fgets(line, sizeof line, stdin)) {
        int64_t collisions = atoll(line);
        double t0 = origin + now, b0 = impulse_sum;
        struct timespec start, end;
        clock_gettime(CLOCK_MONOTONIC, &start);
        run(collisions);
        clock_gettime(CLOCK_MONOTONIC, &end);
        double seconds = (end.tv_sec - start.tv_sec) + 1e-9 * (end.tv_nsec - start.tv_nsec);
        printf("%.6g", collisions / seconds);
        if (with_z) {
            double virial = -sigma2 * (impulse_sum - b0);
            double z = 1.0 + virial / (2.0 * kinetic_energy(1) * (origin + now - t0));
            printf(" %.9f %.3e", z, kinetic_energy(0) / energy0 - 1.0);
        }
        printf("\n");
        fflush(stdout);
    }
    return 0;
}
