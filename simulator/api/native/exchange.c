/* Plain lockstep's steady exchange on a thread of its own: the step's measurements sent and the
 * clients' usual answers read and written onto the target board while the step thread computes
 * the next step's first position stage (simulator/api/exchange.py says when it is used and what
 * Python does around it).
 *
 * The thread sends each robot's frame (one non-blocking send), then reads the answers. An
 * answer is taken here only when it is exactly one whole frame of the robot's usual request:
 * the body's size and its fixed bytes as the robot's template (the bytes between the 8-byte
 * little-endian targets), every target finite. Its targets are copied into the robot's span of
 * the board. Anything else is handed back to Python with the bytes received: more than one
 * frame, another layout, an empty request, the end of the stream; a send the socket did not
 * take whole; an error. A frame still open when the deadline passes is handed back too. A read
 * that ends inside a frame acknowledges it at once (TCP_QUICKACK) and reads once more, as the
 * Python reader does for clients that write a request's length and body apart without
 * TCP_NODELAY.
 *
 * Hand-overs between the two threads are flags in shared memory: each side spins for a while
 * before it sleeps on a futex, so a step that comes back within that time costs no system call
 * and no wake-up between processors. The engine's thread spins for the next step up to
 * ``spin_s`` (the clients are idle while the world steps); the step thread spins for the
 * answers up to ``wait_spin_s`` only, since the clients may need the CPUs it would spin on.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <linux/futex.h>
#include <math.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <pthread.h>
#include <sched.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/epoll.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#define MAX_ROBOTS 64
#define BUFFER_BYTES 65536

enum { PENDING = 0, TAKEN = 1, HANDED = 2, RECV_ERROR = 3, SEND_SHORT = 4, SEND_ERROR = 5 };

typedef struct {
    int fd;
    int body_size;              /* the usual request's body */
    unsigned char *reference;   /* a usual body: its fixed bytes are compared */
    int values;                 /* targets in it */
    int *offsets;               /* where each 8-byte target starts in the body */
    double *destination;        /* the robot's span of the board */
    unsigned char *buffer;      /* bytes received this step */
    const unsigned char *frame; /* this step's measurement */
    int64_t frame_size;
} robot_t;

typedef struct {
    /* results of the last exchange, per robot (read by Python through ex_results) */
    int32_t status[MAX_ROBOTS];
    int32_t error[MAX_ROBOTS];    /* errno of a failed send or receive */
    int64_t sent[MAX_ROBOTS];     /* bytes of the measurement written */
    int64_t received[MAX_ROBOTS]; /* bytes received (in the buffer unless TAKEN) */
    double sent_at[MAX_ROBOTS];   /* CLOCK_MONOTONIC seconds: the send returned */
    double first_at[MAX_ROBOTS];  /* the answer's first bytes seen */
    double answered_at[MAX_ROBOTS];
    robot_t robots[MAX_ROBOTS];
    int count;
    int go, done, stop;                   /* futex words */
    int io_sleeping, step_sleeping;
    int64_t deadline_ns;                  /* the wait's end; INT64_MAX until ex_wait sets it */
    double spin_s, wait_spin_s;
    pthread_t thread;
    int epoll;
    cpu_set_t cpus;
    int pinned;
} engine_t;

static double now_s(void) {
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return (double)now.tv_sec + (double)now.tv_nsec * 1e-9;
}

static int64_t now_ns(void) {
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return (int64_t)now.tv_sec * 1000000000 + now.tv_nsec;
}

static void relax(void) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    __asm__ __volatile__("yield");
#endif
}

static void futex_wait(int *word, int value) {
    syscall(SYS_futex, word, FUTEX_WAIT_PRIVATE, value, NULL, NULL, 0);
}

static void futex_wake(int *word) {
    syscall(SYS_futex, word, FUTEX_WAKE_PRIVATE, 1, NULL, NULL, 0);
}

/* Wait until *word is non-zero: spin for spin_s, then sleep (the other side wakes a sleeper). */
static void await_flag(int *word, int *sleeping, double spin_s) {
    if (__atomic_load_n(word, __ATOMIC_ACQUIRE)) return;
    double until = now_s() + spin_s;
    int turns = 0;
    while (!__atomic_load_n(word, __ATOMIC_ACQUIRE)) {
        relax();
        if (++turns % 64 == 0 && now_s() > until) {
            __atomic_store_n(sleeping, 1, __ATOMIC_SEQ_CST);
            while (!__atomic_load_n(word, __ATOMIC_SEQ_CST)) futex_wait(word, 0);
            __atomic_store_n(sleeping, 0, __ATOMIC_RELAXED);
            return;
        }
    }
}

static void raise_flag(int *word, int *sleeping) {
    __atomic_store_n(word, 1, __ATOMIC_SEQ_CST);
    if (__atomic_load_n(sleeping, __ATOMIC_SEQ_CST)) futex_wake(word);
}

static uint32_t be32(const unsigned char *p) {
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | (uint32_t)p[3];
}

/* TAKEN when the buffer holds one whole usual request (its targets written to the board),
 * PENDING while a frame is still open, else HANDED. */
static int judge(robot_t *robot, int64_t filled) {
    if (filled < 4) return PENDING;
    int64_t size = be32(robot->buffer);
    if (filled < 4 + size) return size + 4 > BUFFER_BYTES ? HANDED : PENDING;
    if (filled != 4 + size || size != robot->body_size) return HANDED;
    const unsigned char *body = robot->buffer + 4;
    int start = 0;
    for (int k = 0; k < robot->values; k++) {
        int at = robot->offsets[k];
        if (memcmp(body + start, robot->reference + start, (size_t)(at - start)) != 0)
            return HANDED;
        start = at + 8;
    }
    if (memcmp(body + start, robot->reference + start, (size_t)(size - start)) != 0)
        return HANDED;
    double targets[MAX_ROBOTS * 8];
    if (robot->values > (int)(sizeof targets / sizeof targets[0])) return HANDED;
    for (int k = 0; k < robot->values; k++) {
        memcpy(&targets[k], body + robot->offsets[k], 8); /* little-endian hosts only */
        if (!isfinite(targets[k])) return HANDED;
    }
    memcpy(robot->destination, targets, (size_t)robot->values * 8);
    return TAKEN;
}

/* Read what robot i has sent; its status afterwards. */
static int take(engine_t *engine, int i) {
    robot_t *robot = &engine->robots[i];
    int64_t filled = engine->received[i];
    int acked = 0;
    for (;;) {
        ssize_t got = recv(robot->fd, robot->buffer + filled, (size_t)(BUFFER_BYTES - filled),
                           MSG_DONTWAIT);
        if (got < 0 && errno == EINTR) continue;
        if (got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            int status = judge(robot, filled);
            if (status != PENDING || filled == 0 || acked) {
                engine->received[i] = filled;
                return status;
            }
            int on = 1; /* inside a frame: acknowledge now and look once more */
            setsockopt(robot->fd, IPPROTO_TCP, TCP_QUICKACK, &on, sizeof on);
            acked = 1;
            continue;
        }
        engine->received[i] = filled;
        if (got < 0) {
            engine->error[i] = errno;
            return RECV_ERROR;
        }
        if (got == 0) return HANDED; /* the end of the stream: Python's read sees it */
        if (filled == 0) engine->first_at[i] = now_s();
        filled += got;
        acked = 0;
        if (filled == BUFFER_BYTES) {
            engine->received[i] = filled;
            return HANDED;
        }
    }
}

/* Send robot i its measurement; its status (PENDING once the frame is written whole). */
static void send_one(engine_t *engine, int i) {
    robot_t *robot = &engine->robots[i];
    engine->received[i] = 0;
    engine->error[i] = 0;
    ssize_t sent;
    do {
        sent = send(robot->fd, robot->frame, (size_t)robot->frame_size, MSG_DONTWAIT | MSG_NOSIGNAL);
    } while (sent < 0 && errno == EINTR);
    engine->sent_at[i] = now_s();
    if (sent < 0 && errno != EAGAIN && errno != EWOULDBLOCK) {
        engine->sent[i] = 0;
        engine->error[i] = errno;
        engine->status[i] = SEND_ERROR;
        return;
    }
    engine->sent[i] = sent < 0 ? 0 : sent;
    engine->status[i] = engine->sent[i] == robot->frame_size ? PENDING : SEND_SHORT;
}

static void exchange(engine_t *engine) {
    int count = engine->count, open = 0;
    for (int i = 0; i < count; i++) send_one(engine, i);
    /* the clients answer as they are woken: most answers are in already */
    for (int i = 0; i < count; i++) {
        if (engine->status[i] != PENDING) continue;
        int status = take(engine, i);
        if (status == PENDING) {
            open++;
            continue;
        }
        engine->status[i] = status;
        engine->answered_at[i] = now_s();
    }
    while (open > 0) {
        struct epoll_event events[MAX_ROBOTS];
        int64_t deadline = __atomic_load_n(&engine->deadline_ns, __ATOMIC_ACQUIRE);
        int64_t left = deadline == INT64_MAX ? 1000000 : deadline - now_ns();
        if (left <= 0) break;
        int timeout_ms = (int)((left + 999999) / 1000000);
        int ready = epoll_wait(engine->epoll, events, MAX_ROBOTS, timeout_ms > 1 ? 1 : timeout_ms);
        if (ready < 0 && errno != EINTR) break;
        for (int k = 0; k < ready; k++) {
            int i = (int)events[k].data.u32;
            if (engine->status[i] != PENDING) continue;
            int status = take(engine, i);
            if (status == PENDING) continue;
            engine->status[i] = status;
            engine->answered_at[i] = now_s();
            open--;
        }
    }
}

static void *run(void *argument) {
    engine_t *engine = argument;
    if (engine->pinned) sched_setaffinity(0, sizeof engine->cpus, &engine->cpus);
    for (;;) {
        await_flag(&engine->go, &engine->io_sleeping, engine->spin_s);
        __atomic_store_n(&engine->go, 0, __ATOMIC_RELAXED);
        if (__atomic_load_n(&engine->stop, __ATOMIC_ACQUIRE)) return NULL;
        exchange(engine);
        raise_flag(&engine->done, &engine->step_sleeping);
    }
}

/* A new engine and its thread (on ``cpus`` when ``ncpus`` > 0), spinning for the next step
 * ``spin_s`` and for the answers ``wait_spin_s`` at most; NULL when it cannot start. */
void *ex_create(const int *cpus, int ncpus, double spin_s, double wait_spin_s) {
    engine_t *engine = calloc(1, sizeof *engine);
    if (engine == NULL) return NULL;
    engine->spin_s = spin_s;
    engine->wait_spin_s = wait_spin_s;
    engine->done = 1;
    engine->epoll = epoll_create1(EPOLL_CLOEXEC);
    CPU_ZERO(&engine->cpus);
    for (int k = 0; k < ncpus; k++) CPU_SET(cpus[k], &engine->cpus);
    engine->pinned = ncpus > 0;
    if (engine->epoll < 0 || pthread_create(&engine->thread, NULL, run, engine) != 0) {
        if (engine->epoll >= 0) close(engine->epoll);
        free(engine);
        return NULL;
    }
    return engine;
}

static void forget(engine_t *engine, robot_t *robot) {
    if (robot->buffer != NULL) epoll_ctl(engine->epoll, EPOLL_CTL_DEL, robot->fd, NULL);
    free(robot->reference);
    free(robot->offsets);
    free(robot->buffer);
    memset(robot, 0, sizeof *robot);
}

/* Robot i of the exchange: its socket, its usual request's body (``reference``, ``body_size``
 * bytes, ``values`` targets at ``offsets``) and its span of the board. 0, or -1 when out of
 * range or out of memory. */
int ex_robot(void *handle, int i, int fd, const unsigned char *reference, int body_size,
             const int *offsets, int values, double *destination) {
    engine_t *engine = handle;
    if (i < 0 || i >= MAX_ROBOTS || body_size < 0 || body_size > BUFFER_BYTES - 4 || values < 0 ||
        values > MAX_ROBOTS * 8)
        return -1;
    for (int k = 0; k < values; k++)
        if (offsets[k] < (k ? offsets[k - 1] + 8 : 0) || offsets[k] + 8 > body_size) return -1;
    robot_t *robot = &engine->robots[i];
    forget(engine, robot);
    robot->reference = malloc((size_t)body_size + 1);
    robot->offsets = malloc(sizeof(int) * ((size_t)values + 1));
    robot->buffer = malloc(BUFFER_BYTES);
    if (!robot->reference || !robot->offsets || !robot->buffer) {
        forget(engine, robot);
        return -1;
    }
    memcpy(robot->reference, reference, (size_t)body_size);
    memcpy(robot->offsets, offsets, sizeof(int) * (size_t)values);
    robot->fd = fd;
    /* watched from now on, edge-triggered: an answer's arrival is seen whether or not the
     * robot is waited for then; one read after the sends takes what came before (exchange) */
    struct epoll_event event = {.events = EPOLLIN | EPOLLET, .data.u32 = (uint32_t)i};
    if (epoll_ctl(engine->epoll, EPOLL_CTL_ADD, fd, &event) != 0) {
        free(robot->buffer);
        robot->buffer = NULL;
        forget(engine, robot);
        return -1;
    }
    robot->body_size = body_size;
    robot->values = values;
    robot->destination = destination;
    return 0;
}

/* Forget every robot (before they are given again). */
void ex_clear(void *handle) {
    engine_t *engine = handle;
    for (int i = 0; i < MAX_ROBOTS; i++) forget(engine, &engine->robots[i]);
}

/* Start an exchange of ``count`` robots: robot i gets frames[spans[2i]:spans[2i+1]] (the
 * buffer stays untouched until ex_wait returns). */
void ex_go(void *handle, int count, const unsigned char *frames, const int64_t *spans) {
    engine_t *engine = handle;
    engine->count = count;
    for (int i = 0; i < count; i++) {
        engine->robots[i].frame = frames + spans[2 * i];
        engine->robots[i].frame_size = spans[2 * i + 1] - spans[2 * i];
    }
    __atomic_store_n(&engine->deadline_ns, INT64_MAX, __ATOMIC_RELAXED);
    __atomic_store_n(&engine->done, 0, __ATOMIC_RELAXED);
    raise_flag(&engine->go, &engine->io_sleeping);
}

/* Wait for the exchange, reading answers until ``wait_s`` from now at the latest; returns the
 * robots whose answer was taken. */
int ex_wait(void *handle, double wait_s) {
    engine_t *engine = handle;
    int64_t deadline = now_ns() + (int64_t)(wait_s * 1e9);
    __atomic_store_n(&engine->deadline_ns, deadline, __ATOMIC_RELEASE);
    await_flag(&engine->done, &engine->step_sleeping, engine->wait_spin_s);
    int taken = 0;
    for (int i = 0; i < engine->count; i++) taken += engine->status[i] == TAKEN;
    return taken;
}

/* The results' arrays, in the order of engine_t's fields; a robot's received bytes. */
void *ex_results(void *handle) { return handle; }

const unsigned char *ex_buffer(void *handle, int i) {
    return ((engine_t *)handle)->robots[i].buffer;
}

/* End the thread and free the engine (no exchange may be in flight). */
void ex_close(void *handle) {
    engine_t *engine = handle;
    __atomic_store_n(&engine->stop, 1, __ATOMIC_RELEASE);
    raise_flag(&engine->go, &engine->io_sleeping);
    pthread_join(engine->thread, NULL);
    ex_clear(handle);
    close(engine->epoll);
    free(engine);
}
