/*
 * alloc_count.c - an LD_PRELOAD library for make bench: counts heap
 * allocations (malloc, calloc, realloc, posix_memalign, aligned_alloc) of
 * the process it is loaded into.
 *
 * SIGUSR2 records a mark (the count at that moment; at most 8 marks). At
 * exit the counts are written to the file named by ROBOELF_ALLOC_OUT as one
 * line "allocs total=N marks=M0,M1,...". The bench sends one SIGUSR2 after
 * start-up and one before asking the process to quit: the difference is
 * the number of allocations made by the periodic cycle.
 *
 * Built by tests/bench.sh: cc -shared -fPIC -o alloc_count.so alloc_count.c
 * -ldl. Not usable under AddressSanitizer (which owns malloc).
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <fcntl.h>
#include <signal.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define MARKS	   8
#define BOOT_BYTES 8192

static atomic_long n_allocs;
static long marks[MARKS];
static atomic_int n_marks;

static void *(*real_malloc)(size_t);
static void *(*real_calloc)(size_t, size_t);
static void *(*real_realloc)(void *, size_t);
static void (*real_free)(void *);
static int (*real_posix_memalign)(void **, size_t, size_t);
static void *(*real_aligned_alloc)(size_t, size_t);

/* dlsym() may allocate before the real functions are known. */
static _Alignas(16) char boot[BOOT_BYTES];
static size_t boot_used;
static int resolving;

static void *boot_alloc(size_t n)
{
	void *p;

	n = (n + 15) & ~(size_t)15;
	if (boot_used + n > sizeof(boot))
		return NULL;
	p = boot + boot_used;
	boot_used += n;
	return p;
}

static int in_boot(const void *p)
{
	return (const char *)p >= boot && (const char *)p < boot + sizeof(boot);
}

static void resolve(void)
{
	if (real_malloc || resolving)
		return;
	resolving = 1;
	real_calloc = (void *(*)(size_t, size_t))dlsym(RTLD_NEXT, "calloc");
	real_malloc = (void *(*)(size_t))dlsym(RTLD_NEXT, "malloc");
	real_realloc = (void *(*)(void *, size_t))dlsym(RTLD_NEXT, "realloc");
	real_free = (void (*)(void *))dlsym(RTLD_NEXT, "free");
	real_posix_memalign = (int (*)(void **, size_t, size_t))dlsym(
	    RTLD_NEXT, "posix_memalign");
	real_aligned_alloc =
	    (void *(*)(size_t, size_t))dlsym(RTLD_NEXT, "aligned_alloc");
	resolving = 0;
}

void *malloc(size_t n)
{
	resolve();
	if (!real_malloc)
		return boot_alloc(n);
	atomic_fetch_add(&n_allocs, 1);
	return real_malloc(n);
}

void *calloc(size_t n, size_t m)
{
	resolve();
	if (!real_calloc)
		return boot_alloc(n * m); /* static: already zero */
	atomic_fetch_add(&n_allocs, 1);
	return real_calloc(n, m);
}

void *realloc(void *p, size_t n)
{
	resolve();
	if (in_boot(p)) {
		void *q = malloc(n);

		if (q)
			memcpy(q, p, n); /* boot blocks are never large */
		return q;
	}
	atomic_fetch_add(&n_allocs, 1);
	return real_realloc(p, n);
}

void free(void *p)
{
	if (!p || in_boot(p))
		return;
	resolve();
	real_free(p);
}

int posix_memalign(void **out, size_t align, size_t n)
{
	resolve();
	atomic_fetch_add(&n_allocs, 1);
	return real_posix_memalign(out, align, n);
}

void *aligned_alloc(size_t align, size_t n)
{
	resolve();
	atomic_fetch_add(&n_allocs, 1);
	return real_aligned_alloc(align, n);
}

static void on_mark(int sig)
{
	int k = atomic_fetch_add(&n_marks, 1);

	(void)sig;
	if (k < MARKS)
		marks[k] = atomic_load(&n_allocs);
}

__attribute__((constructor)) static void alloc_count_init(void)
{
	struct sigaction sa;

	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = on_mark;
	sa.sa_flags = SA_RESTART;
	sigemptyset(&sa.sa_mask);
	sigaction(SIGUSR2, &sa, NULL);
}

__attribute__((destructor)) static void alloc_count_report(void)
{
	const char *path = getenv("ROBOELF_ALLOC_OUT");
	char line[512];
	int n, len, fd, k = atomic_load(&n_marks);

	if (!path || !*path)
		return;
	len = snprintf(line, sizeof(line),
		       "allocs total=%ld marks=", atomic_load(&n_allocs));
	for (int i = 0; i < k && i < MARKS && len < (int)sizeof(line) - 24; i++)
		len += snprintf(line + len, sizeof(line) - (size_t)len, "%s%ld",
				i ? "," : "", marks[i]);
	len += snprintf(line + len, sizeof(line) - (size_t)len, "\n");
	fd = open(path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
	if (fd < 0)
		return;
	n = (int)write(fd, line, (size_t)len);
	(void)n;
	close(fd);
}
