/*
 * replay.c: a main() for the harnesses without libFuzzer, so that `make
 * test` runs each seed corpus with the project's own compiler and
 * sanitisers: `build/san/fuzz/fuzz_model tests/fuzz/corpus/fuzz_model`.
 * Each argument is a file or a directory of files, each file one input.
 * Exits 0 after running every input, 1 if an argument cannot be read or
 * holds no input (an empty corpus tests nothing); a broken invariant aborts.
 */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "fuzz.h"

/* The replay's own LLVMFuzzerInitialize, for harnesses that have none (libFuzzer has it weak too). */
__attribute__((weak)) int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    return 0;
}

static int run_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "replay: cannot open %s\n", path);
        return -1;
    }
    size_t cap = 4096, len = 0, got;
    char *buf = malloc(cap);
    while (buf && (got = fread(buf + len, 1, cap - len, f)) > 0) {
        len += got;
        if (len == cap) {
            char *more = realloc(buf, cap *= 2);
            if (!more)
                free(buf);
            buf = more;
        }
    }
    int bad = !buf || ferror(f);
    fclose(f);
    if (bad) {
        free(buf);
        fprintf(stderr, "replay: cannot read %s\n", path);
        return -1;
    }
    /* An exact-size copy, so that AddressSanitizer sees any read past the input. */
    uint8_t *data = malloc(len ? len : 1);
    if (!data) {
        free(buf);
        return -1;
    }
    memcpy(data, buf, len);
    free(buf);
    LLVMFuzzerTestOneInput(data, len);
    free(data);
    return 0;
}

/* Runs a file, or every regular file of a directory in name order; returns the inputs run, or -1. */
static long run_path(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        fprintf(stderr, "replay: no such file or directory: %s\n", path);
        return -1;
    }
    if (!S_ISDIR(st.st_mode))
        return run_file(path) == 0 ? 1 : -1;
    struct dirent **names;
    int n = scandir(path, &names, NULL, alphasort);
    if (n < 0) {
        fprintf(stderr, "replay: cannot read the directory %s\n", path);
        return -1;
    }
    long runs = 0;
    for (int i = 0; i < n; i++) {
        char file[4096];
        snprintf(file, sizeof file, "%s/%s", path, names[i]->d_name);
        if (names[i]->d_name[0] != '.' && stat(file, &st) == 0 && S_ISREG(st.st_mode))
            runs = runs < 0 || run_file(file) < 0 ? -1 : runs + 1;
        free(names[i]);
    }
    free(names);
    return runs;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s FILE_OR_DIR...\n", argv[0]);
        return 2;
    }
    LLVMFuzzerInitialize(&argc, &argv);
    for (int i = 1; i < argc; i++) {
        long runs = run_path(argv[i]);
        if (runs <= 0) {
            fprintf(stderr, "replay: %s: %s\n", argv[i], runs == 0 ? "no input in it" : "failed");
            return 1;
        }
        printf("%s: %ld inputs replayed, all invariants held\n", argv[i], runs);
    }
    return 0;
}
