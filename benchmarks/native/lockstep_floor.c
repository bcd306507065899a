/* The serial floor of lockstep on this machine: a lockstep server in C that does nothing but
 * what lockstep's step thread must do between two steps, with a busy loop the length of the
 * world's step in place of the world.
 *
 * usage: lockstep_floor PORT CLIENTS STEPS STEP_US MEASUREMENT_BYTES WELCOME_HEX [CPU]
 * It listens on 127.0.0.1:PORT, takes CLIENTS connections (each greeted with the 8 bytes of
 * WELCOME_HEX, then its first frame, the request that enables its sensors, read), then STEPS
 * times: busy for STEP_US microseconds, sends each client a frame of MEASUREMENT_BYTES (a 4-byte
 * big-endian length and a body), and waits until each client's answer frame has arrived whole.
 * The first tenth of the steps is untimed. Prints one JSON line: the ratio of the busy time to
 * the wall time (no serial lockstep server with one socket per robot can do better with these
 * clients here), and per step the wall time beyond the busy loop, the step thread's CPU time
 * sending and the wall time waiting. Exit 2: bad arguments; 3: a client went away.
 */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sched.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/epoll.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#define MAX_CLIENTS 64

typedef struct {
    int fd;
    unsigned char *buffer;
    size_t size, filled;
} client_t;

static double clock_s(clockid_t which) {
    struct timespec now;
    clock_gettime(which, &now);
    return (double)now.tv_sec + (double)now.tv_nsec * 1e-9;
}

static uint32_t be32(const unsigned char *p) {
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | (uint32_t)p[3];
}

/* Reads what has arrived; returns the whole frames taken off the buffer, -1 when closed. */
static int take_frames(client_t *client) {
    for (;;) {
        if (client->filled == client->size)
            client->buffer = realloc(client->buffer, client->size *= 2);
        ssize_t got = recv(client->fd, client->buffer + client->filled,
                           client->size - client->filled, MSG_DONTWAIT);
        if (got < 0 && errno == EINTR) continue;
        if (got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
        if (got <= 0) return -1;
        client->filled += (size_t)got;
    }
    int frames = 0;
    size_t start = 0;
    while (client->filled - start >= 4) {
        size_t end = start + 4 + be32(client->buffer + start);
        if (end > client->filled) break;
        start = end;
        frames++;
    }
    memmove(client->buffer, client->buffer + start, client->filled - start);
    client->filled -= start;
    if (client->filled > 0) { /* inside a frame: acknowledge now, as the API server does for
                                 clients that write the length and the body apart (Nagle) */
        int on = 1;
        setsockopt(client->fd, IPPROTO_TCP, TCP_QUICKACK, &on, sizeof on);
    }
    return frames;
}

static int send_all(int fd, const unsigned char *data, size_t size) {
    while (size > 0) {
        ssize_t sent = send(fd, data, size, MSG_NOSIGNAL);
        if (sent < 0 && errno == EINTR) continue;
        if (sent < 0) return -1;
        data += sent;
        size -= (size_t)sent;
    }
    return 0;
}

int main(int argc, char **argv) {
    if (argc < 7 || strlen(argv[6]) != 16) {
        fprintf(stderr, "usage: lockstep_floor PORT CLIENTS STEPS STEP_US MEASUREMENT_BYTES "
                        "WELCOME_HEX [CPU]\n");
        return 2;
    }
    int port = atoi(argv[1]), count = atoi(argv[2]), steps = atoi(argv[3]);
    double step_s = atof(argv[4]) * 1e-6;
    long measurement = atol(argv[5]);
    if (port <= 0 || port > 65535 || count < 1 || count > MAX_CLIENTS || steps < 10 ||
        step_s < 0 || measurement < 1 || measurement > (1 << 24)) {
        fprintf(stderr, "lockstep_floor: an argument is out of range\n");
        return 2;
    }
    unsigned char welcome[8];
    for (int i = 0; i < 8; i++) sscanf(argv[6] + 2 * i, "%2hhx", &welcome[i]);
    if (argc > 7) {
        cpu_set_t cpus;
        CPU_ZERO(&cpus);
        CPU_SET(atoi(argv[7]), &cpus);
        sched_setaffinity(0, sizeof cpus, &cpus);
    }

    int listener = socket(AF_INET, SOCK_STREAM, 0), on = 1;
    setsockopt(listener, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
    struct sockaddr_in address = {0};
    address.sin_family = AF_INET;
    address.sin_port = htons((uint16_t)port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (bind(listener, (struct sockaddr *)&address, sizeof address) < 0 ||
        listen(listener, MAX_CLIENTS) < 0) {
        perror("lockstep_floor: listen");
        return 2;
    }
    int poll = epoll_create1(0);
    client_t clients[MAX_CLIENTS];
    for (int i = 0; i < count; i++) {
        client_t *client = &clients[i];
        client->fd = accept(listener, NULL, NULL);
        setsockopt(client->fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);
        client->size = 1 << 16;
        client->filled = 0;
        client->buffer = malloc(client->size);
        if (send_all(client->fd, welcome, 8) < 0) return 3;
        struct epoll_event event = {.events = EPOLLIN, .data.u32 = (uint32_t)i};
        epoll_ctl(poll, EPOLL_CTL_ADD, client->fd, &event);
    }
    for (int i = 0; i < count; i++) { /* each client's enable request */
        int got = 0;
        while (got == 0) {
            struct epoll_event events[MAX_CLIENTS];
            epoll_wait(poll, events, MAX_CLIENTS, 1000);
            got = take_frames(&clients[i]);
            if (got < 0) return 3;
        }
    }

    unsigned char *frame = calloc(1, (size_t)measurement + 4);
    frame[0] = (unsigned char)(measurement >> 24);
    frame[1] = (unsigned char)(measurement >> 16);
    frame[2] = (unsigned char)(measurement >> 8);
    frame[3] = (unsigned char)measurement;
    int warmup = steps / 10;
    double started = 0, sending = 0, waiting = 0;
    for (int step = 0; step < warmup + steps; step++) {
        if (step == warmup) started = clock_s(CLOCK_MONOTONIC), sending = waiting = 0;
        double busy = clock_s(CLOCK_MONOTONIC);
        while (clock_s(CLOCK_MONOTONIC) - busy < step_s) {
        }
        double cpu = clock_s(CLOCK_THREAD_CPUTIME_ID);
        for (int i = 0; i < count; i++)
            if (send_all(clients[i].fd, frame, (size_t)measurement + 4) < 0) return 3;
        double wait = clock_s(CLOCK_MONOTONIC);
        sending += clock_s(CLOCK_THREAD_CPUTIME_ID) - cpu;
        int answered = 0;
        while (answered < count) {
            struct epoll_event events[MAX_CLIENTS];
            int ready = epoll_wait(poll, events, MAX_CLIENTS, 10000);
            if (ready <= 0) return 3;
            for (int k = 0; k < ready; k++) {
                int got = take_frames(&clients[events[k].data.u32]);
                if (got < 0) return 3;
                answered += got;
            }
        }
        waiting += clock_s(CLOCK_MONOTONIC) - wait;
    }
    double wall = clock_s(CLOCK_MONOTONIC) - started;
    printf("{\"ratio\": %.4f, \"overhead_us_per_step\": %.1f, \"send_cpu_us_per_step\": %.1f, "
           "\"wait_us_per_step\": %.1f, \"steps\": %d, \"step_us\": %.1f, "
           "\"measurement_bytes\": %ld, \"clients\": %d}\n",
           step_s * steps / wall, (wall / steps - step_s) * 1e6, sending / steps * 1e6,
           waiting / steps * 1e6, steps, step_s * 1e6, measurement, count);
    for (int i = 0; i < count; i++) close(clients[i].fd);
    return 0;
}
