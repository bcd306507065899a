/*
 * The start gate of a robot container: its entry point until the match lets the robot's own
 * program run.
 *
 *     start_gate DIR -- PROGRAM [ARG...]
 *
 * waits until the file DIR/go exists (the orchestrator writes it once the robot's network
 * namespace has its bandwidth limits), then replaces itself with PROGRAM (found on PATH, as
 * the engine finds an entry point), so that nothing of the robot runs unshaped and the robot's
 * program is the container's first process as without the gate. Statically linked: it runs in
 * any image, with no shell or C library of the image's.
 *
 * Exit codes as a shell's: 127 the program was not found, 126 it could not be run, 125 bad
 * arguments.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

int main(int argc, char **argv) {
    if (argc < 4 || strcmp(argv[2], "--") != 0) {
        fprintf(stderr, "start gate: usage: %s DIR -- PROGRAM [ARG...]\n", argv[0]);
        return 125;
    }
    char go[4096];
    if (snprintf(go, sizeof go, "%s/go", argv[1]) >= (int)sizeof go) {
        fprintf(stderr, "start gate: folder name too long\n");
        return 125;
    }
    const struct timespec pause = {0, 1000000}; /* 1 ms between looks */
    while (access(go, F_OK) != 0) {
        nanosleep(&pause, NULL);
    }
    execvp(argv[3], argv + 3);
    int error = errno;
    fprintf(stderr, "start gate: cannot run %s: %s\n", argv[3], strerror(error));
    return error == ENOENT ? 127 : 126;
}
