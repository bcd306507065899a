/* One robot's bench client in C: what benchmarks/api.py's Python clients do, without an
 * interpreter between the socket calls, so that a 2-CPU bench machine measures the server and
 * not its clients (the league's own test client, controllers/player/robot_client.cpp of
 * hlvs_webots, is compiled code too).
 *
 * usage: bench_client PORT FRAMES_FILE STYLE [CPU,CPU,...]
 *   FRAMES_FILE  the 8-byte greeting the server sends, then length-prefixed frames (4-byte
 *                big-endian length, body): the request that enables the sensors, then the
 *                answers, sent in turn, one for each measurement received (measurements are
 *                framed, not decoded)
 *   STYLE        "framed": TCP_NODELAY, each frame in one write (the Python bench clients);
 *                "league": no TCP_NODELAY, the length and the body in two writes (as the
 *                league's robot_client.cpp)
 *   CPU,...      the CPUs it may run on (default: any)
 * It connects (retrying while the server starts), reads the greeting, sends the enable request
 * and answers until the server closes; then prints one JSON line and exits 0: the answers sent,
 * the median of answer_s (a measurement's arrival to its answer's last write returned: this
 * client's part of the server's round trip) and of round_trip_s (that return to the next
 * measurement's arrival: what the league's client waits for in RobotClient::receive), as the
 * bench's Python league-style clients report them. Exit 2: bad arguments or frames file; 3: no
 * session on the port within 60 s.
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
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

typedef struct {
    const unsigned char *data; /* length prefix and body */
    size_t size;               /* 4 + body */
} frame_t;

static int write_all(int fd, const unsigned char *data, size_t size) {
    while (size > 0) {
        ssize_t sent = send(fd, data, size, MSG_NOSIGNAL);
        if (sent < 0) {
            if (errno == EINTR) continue;
            return -1;
        }
        data += sent;
        size -= (size_t)sent;
    }
    return 0;
}

static int send_frame(int fd, const frame_t *frame, int league) {
    if (!league) return write_all(fd, frame->data, frame->size);
    if (write_all(fd, frame->data, 4) < 0) return -1; /* the length, then the body */
    return write_all(fd, frame->data + 4, frame->size - 4);
}

static uint32_t be32(const unsigned char *p) {
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | (uint32_t)p[3];
}

static double now_s(void) {
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return (double)now.tv_sec + (double)now.tv_nsec * 1e-9;
}

typedef struct {
    double *values;
    size_t count, capacity;
} samples_t;

static void add(samples_t *samples, double value) {
    if (samples->count == samples->capacity) {
        samples->capacity = samples->capacity ? samples->capacity * 2 : 4096;
        samples->values = realloc(samples->values, samples->capacity * sizeof(double));
    }
    samples->values[samples->count++] = value;
}

static int ascending(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void print_median(const char *name, samples_t *samples) {
    if (samples->count == 0) {
        printf("\"%s\": null", name);
        return;
    }
    qsort(samples->values, samples->count, sizeof(double), ascending);
    printf("\"%s\": %.9f", name, samples->values[samples->count / 2]);
}

static int read_exact(int fd, unsigned char *into, size_t size) {
    while (size > 0) {
        ssize_t got = recv(fd, into, size, 0);
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) return -1;
        into += got;
        size -= (size_t)got;
    }
    return 0;
}

int main(int argc, char **argv) {
    if (argc < 4) {
        fprintf(stderr, "usage: bench_client PORT FRAMES_FILE framed|league [CPU,...]\n");
        return 2;
    }
    int port = atoi(argv[1]);
    int league = strcmp(argv[3], "league") == 0;
    if (port <= 0 || port > 65535 || (!league && strcmp(argv[3], "framed") != 0)) {
        fprintf(stderr, "bench_client: bad port %s or style %s\n", argv[1], argv[3]);
        return 2;
    }
    if (argc > 4 && argv[4][0]) {
        cpu_set_t cpus;
        CPU_ZERO(&cpus);
        for (char *item = strtok(argv[4], ","); item; item = strtok(NULL, ","))
            CPU_SET(atoi(item), &cpus);
        sched_setaffinity(0, sizeof cpus, &cpus);
    }

    FILE *file = fopen(argv[2], "rb");
    if (!file) {
        perror(argv[2]);
        return 2;
    }
    fseek(file, 0, SEEK_END);
    long length = ftell(file);
    fseek(file, 0, SEEK_SET);
    unsigned char *blob = malloc(length > 0 ? (size_t)length : 1);
    if (length < 8 + 4 || fread(blob, 1, (size_t)length, file) != (size_t)length) {
        fprintf(stderr, "bench_client: %s: too short or unreadable\n", argv[2]);
        return 2;
    }
    fclose(file);
    size_t count = 0, capacity = 256;
    frame_t *frames = malloc(capacity * sizeof *frames);
    for (size_t at = 8; at < (size_t)length;) {
        if ((size_t)length - at < 4 || be32(blob + at) > (size_t)length - at - 4) {
            fprintf(stderr, "bench_client: %s: a frame runs past the end at byte %zu\n", argv[2],
                    at);
            return 2;
        }
        if (count == capacity) frames = realloc(frames, (capacity *= 2) * sizeof *frames);
        frames[count].data = blob + at;
        frames[count].size = 4 + be32(blob + at);
        at += frames[count++].size;
    }
    if (count < 2) {
        fprintf(stderr, "bench_client: %s: needs the enable request and an answer\n", argv[2]);
        return 2;
    }

    struct sockaddr_in address = {0};
    address.sin_family = AF_INET;
    address.sin_port = htons((uint16_t)port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    int fd = -1;
    for (int attempt = 0; attempt < 240; attempt++) {
        fd = socket(AF_INET, SOCK_STREAM, 0);
        unsigned char greeting[8];
        if (connect(fd, (struct sockaddr *)&address, sizeof address) == 0 &&
            read_exact(fd, greeting, 8) == 0 && memcmp(greeting, blob, 8) == 0)
            break;
        close(fd);
        fd = -1;
        usleep(250000);
    }
    if (fd < 0) {
        fprintf(stderr, "bench_client: no session on port %d\n", port);
        return 3;
    }
    int on = 1;
    if (!league) setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);
    if (send_frame(fd, &frames[0], league) < 0) return 0;

    size_t size = 1 << 16, filled = 0;
    unsigned char *buffer = malloc(size);
    unsigned long answered = 0;
    samples_t answer_s = {0}, round_trip_s = {0};
    double written = 0; /* when the last answer's last write returned */
    for (;;) {
        if (filled == size) buffer = realloc(buffer, size *= 2); /* a camera image */
        ssize_t got = recv(fd, buffer + filled, size - filled, 0);
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) break;
        double arrived = now_s();
        filled += (size_t)got;
        size_t start = 0;
        while (filled - start >= 4) {
            size_t end = start + 4 + be32(buffer + start);
            if (end > filled) break;
            start = end;
            if (written > 0) add(&round_trip_s, arrived - written);
            if (send_frame(fd, &frames[1 + answered % (count - 1)], league) < 0) goto closed;
            written = now_s();
            add(&answer_s, written - arrived);
            answered++;
        }
        if (start) {
            memmove(buffer, buffer + start, filled - start);
            filled -= start;
        }
    }
closed:
    printf("{\"answered\": %lu, ", answered);
    print_median("answer_s", &answer_s);
    printf(", ");
    print_median("round_trip_s", &round_trip_s);
    printf("}\n");
    return 0;
}
