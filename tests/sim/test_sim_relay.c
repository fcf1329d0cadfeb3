/*
 * test_sim_relay.c - galil-sim's virtual E-stop relay (sim_relay.h): the
 * byte protocols of relays-and-serial.md, fed to the pure decoder and
 * through a real pseudo-terminal opened the way the supervisor's tty
 * back-end opens it (O_RDWR | O_NOCTTY, cfmakeraw); unplug and write-fail
 * faults; the symbolic link.
 */
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "base_clock.h"
#include "gl_err.h"
#include "sim_relay.h"

#define DEADLINE_MS 2000 /* generous: a pty hop takes microseconds */
#define QUIET_MS    100	 /* "no answer" is judged over this */

struct fx {
	char dir[64];
	char link[128];
	struct sim_relay *r;
	int fd; /* the host side (slave) */
	char events[4096];
};

static void on_event(void *ud, const char *line)
{
	struct fx *f = ud;
	size_t n = strlen(f->events);

	snprintf(f->events + n, sizeof(f->events) - n, "%s\n", line);
}

static long long now_ms(void)
{
	return (long long)base_now_ms();
}

static int open_host(const char *path)
{
	struct termios tio;
	int fd = open(path, O_RDWR | O_NOCTTY | O_CLOEXEC);

	if (fd < 0)
		return -1;
	tcgetattr(fd, &tio);
	cfmakeraw(&tio);
	tio.c_cflag |= CLOCAL | CREAD;
	tcsetattr(fd, TCSANOW, &tio);
	return fd;
}

static int teardown(void **state);

/* On failure the fixture is undone here: cmocka skips teardown then. */
static int setup_proto(void **state, enum sim_relay_proto proto)
{
	struct fx *f = calloc(1, sizeof(*f));
	char err[256];

	if (!f)
		return -1;
	*state = f;
	f->fd = -1;
	snprintf(f->dir, sizeof(f->dir), "/tmp/test_sim_relay.XXXXXX");
	if (!mkdtemp(f->dir)) {
		free(f);
		return -1;
	}
	snprintf(f->link, sizeof(f->link), "%s/relay", f->dir);
	if (sim_relay_new(&f->r, proto, on_event, f) == 0 &&
	    sim_relay_attach(f->r, f->link, err, sizeof(err)) == 0) {
		f->fd = open_host(f->link);
		if (f->fd >= 0)
			return 0;
	}
	teardown(state);
	return -1;
}

static int setup_devantech(void **state)
{
	return setup_proto(state, SIM_RELAY_DEVANTECH);
}

static int setup_icstation(void **state)
{
	return setup_proto(state, SIM_RELAY_ICSTATION);
}

static int setup_lcus(void **state)
{
	return setup_proto(state, SIM_RELAY_LCUS);
}

static int setup_kmtronic(void **state)
{
	return setup_proto(state, SIM_RELAY_KMTRONIC);
}

static int teardown(void **state)
{
	struct fx *f = *state;

	if (f->fd >= 0)
		close(f->fd);
	sim_relay_free(f->r);
	unlink(f->link);
	rmdir(f->dir);
	free(f);
	return 0;
}

static void send_bytes(struct fx *f, const uint8_t *b, size_t n)
{
	assert_int_equal(write(f->fd, b, n), (ssize_t)n);
}

/* Service the relay until @want bytes were consumed (deadline). */
static void pump(struct fx *f, int want)
{
	long long end = now_ms() + DEADLINE_MS;
	int got = 0;

	while (got < want) {
		struct pollfd p = {sim_relay_fd(f->r), POLLIN, 0};
		int n;

		if (now_ms() > end)
			fail_msg("relay consumed %d of %d bytes", got, want);
		poll(&p, 1, 10);
		n = sim_relay_service(f->r);
		assert_true(n >= 0);
		got += n;
	}
}

/* Read exactly @n reply bytes from the host side (deadline). */
static void expect_reply(struct fx *f, const uint8_t *want, size_t n)
{
	uint8_t buf[16];
	size_t got = 0;
	long long end = now_ms() + DEADLINE_MS;

	while (got < n) {
		struct pollfd p = {f->fd, POLLIN, 0};
		ssize_t r;

		if (now_ms() > end)
			fail_msg("got %zu of %zu reply bytes", got, n);
		if (poll(&p, 1, 10) <= 0)
			continue;
		r = read(f->fd, buf + got, n - got);
		assert_true(r > 0);
		got += (size_t)r;
	}
	assert_memory_equal(buf, want, n);
}

/* Nothing arrives on the host side within QUIET_MS. */
static void expect_silence(struct fx *f)
{
	struct pollfd p = {f->fd, POLLIN, 0};

	assert_int_equal(poll(&p, 1, QUIET_MS), 0);
}

static void say(struct fx *f, const uint8_t *b, size_t n)
{
	send_bytes(f, b, n);
	pump(f, (int)n);
}

/* ---- devantech ---------------------------------------------------------- */

static void test_devantech_on_off_query(void **state)
{
	struct fx *f = *state;
	const uint8_t q = 0x5B;

	assert_int_equal(sim_relay_power(f->r), 0); /* starts off */
	say(f, (const uint8_t[]){0x65}, 1);
	assert_int_equal(sim_relay_power(f->r), 1);
	say(f, &q, 1);
	expect_reply(f, (const uint8_t[]){0x01}, 1);
	say(f, (const uint8_t[]){0x66}, 1); /* relay 2: no power change */
	say(f, &q, 1);
	expect_reply(f, (const uint8_t[]){0x03}, 1);
	say(f, (const uint8_t[]){0x6F}, 1);
	assert_int_equal(sim_relay_power(f->r), 0);
	say(f, &q, 1);
	expect_reply(f, (const uint8_t[]){0x02}, 1);
	say(f, (const uint8_t[]){0x64}, 1); /* all on */
	assert_int_equal(sim_relay_power(f->r), 1);
	say(f, (const uint8_t[]){0x6E}, 1); /* all off */
	assert_int_equal(sim_relay_power(f->r), 0);
	say(f, (const uint8_t[]){0x5C, 0x05}, 2); /* set states */
	assert_int_equal(sim_relay_power(f->r), 1);
	assert_non_null(strstr(f->events, "relay on (byte 0x65)\n"
					  "relay off (byte 0x6f)\n"));
}

static void test_devantech_unknown_byte_ignored(void **state)
{
	struct fx *f = *state;

	say(f, (const uint8_t[]){0x20, 0x65}, 2);
	assert_int_equal(sim_relay_power(f->r), 1);
	assert_non_null(strstr(f->events, "relay ignored byte 0x20: unknown "
					  "devantech command\n"));
}

/* Unplugged: host writes fail with EIO, the node and the link vanish,
 * power is off. Plugged back: a new pty behind the same link, relay off. */
static void test_unplug_and_replug(void **state)
{
	struct fx *f = *state;
	char tty[64], err[256], target[128];
	struct stat st;
	ssize_t n;

	say(f, (const uint8_t[]){0x65}, 1);
	snprintf(tty, sizeof(tty), "%s", sim_relay_tty(f->r));
	assert_int_equal(
	    sim_relay_set_fault(f->r, SIM_RELAY_UNPLUG, err, sizeof(err)), 0);
	assert_int_equal(sim_relay_power(f->r), 0);
	assert_int_equal(sim_relay_fd(f->r), -1);
	assert_string_equal(sim_relay_tty(f->r), "");
	errno = 0;
	assert_int_equal(write(f->fd, "\x65", 1), -1);
	assert_int_equal(errno, EIO);
	assert_int_equal(stat(tty, &st), -1);
	assert_int_equal(errno, ENOENT);
	assert_int_equal(lstat(f->link, &st), -1);
	assert_int_equal(sim_relay_set(f->r, 1), GL_ERR_RELAY);
	assert_non_null(strstr(f->events, "relay unplugged\nrelay off "
					  "(unplugged)\n"));
	close(f->fd);
	f->fd = -1;

	assert_int_equal(
	    sim_relay_set_fault(f->r, SIM_RELAY_OK, err, sizeof(err)), 0);
	n = readlink(f->link, target, sizeof(target) - 1);
	assert_true(n > 0);
	target[n] = '\0';
	assert_string_equal(target, sim_relay_tty(f->r));
	assert_int_equal(sim_relay_power(f->r), 0);
	f->fd = open_host(f->link);
	assert_true(f->fd >= 0);
	say(f, (const uint8_t[]){0x65}, 1);
	assert_int_equal(sim_relay_power(f->r), 1);
}

/* Write failing: the device stays, bytes are swallowed, no answer, power
 * off; repaired, it obeys again with every relay off. */
static void test_writefail(void **state)
{
	struct fx *f = *state;
	char err[256];
	struct stat st;

	say(f, (const uint8_t[]){0x65}, 1);
	assert_int_equal(
	    sim_relay_set_fault(f->r, SIM_RELAY_WRITEFAIL, err, sizeof(err)),
	    0);
	assert_int_equal(sim_relay_power(f->r), 0);
	assert_int_equal(stat(f->link, &st), 0);
	say(f, (const uint8_t[]){0x65, 0x5B}, 2);
	assert_int_equal(sim_relay_power(f->r), 0);
	expect_silence(f);
	assert_int_equal(
	    sim_relay_set_fault(f->r, SIM_RELAY_OK, err, sizeof(err)), 0);
	assert_int_equal(sim_relay_power(f->r), 0);
	say(f, (const uint8_t[]){0x5B}, 1);
	expect_reply(f, (const uint8_t[]){0x00}, 1);
	say(f, (const uint8_t[]){0x65}, 1);
	assert_int_equal(sim_relay_power(f->r), 1);
}

#define WEDGE_HOLD_MS 200 /* a wedge is judged over this */

/* A second host descriptor: plain raw termios, non-blocking. */
static int open_host_nonblock(const char *path)
{
	struct termios tio;
	int fd = open(path, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);

	if (fd < 0)
		return -1;
	tcgetattr(fd, &tio);
	cfmakeraw(&tio);
	tcsetattr(fd, TCSANOW, &tio);
	return fd;
}

/*
 * Wedged: the board reads nothing. A byte the host writes stays queued in
 * the pty (checked for WEDGE_HOLD_MS, the board serviced meanwhile), the
 * relay keeps its state (on: motor power stays), the control port cannot
 * switch it, and the host's writes end up refused (EAGAIN: they would
 * block). Repaired: what was queued is discarded unread, relays off, the
 * board reads again.
 */
static void test_wedge(void **state)
{
	struct fx *f = *state;
	long long end;
	char err[256];
	uint8_t chunk[256];
	long total = 1;
	ssize_t w;
	int fd;

	say(f, (const uint8_t[]){0x65}, 1);
	assert_int_equal(
	    sim_relay_set_fault(f->r, SIM_RELAY_WEDGE, err, sizeof(err)), 0);
	assert_int_equal(sim_relay_get_fault(f->r), SIM_RELAY_WEDGE);
	assert_int_equal(sim_relay_fd(f->r), -1);
	assert_int_equal(sim_relay_power(f->r), 1);
	fd = open_host_nonblock(f->link);
	assert_true(fd >= 0);
	assert_int_equal(write(fd, "\x6f", 1), 1); /* relay off: not read */
	/* the pty hands the byte to the board's side asynchronously */
	end = now_ms() + DEADLINE_MS;
	while (sim_relay_queued(f->r) < 1) {
		if (now_ms() > end)
			fail_msg("the byte never reached the board's side");
		poll(NULL, 0, 1);
	}
	end = now_ms() + WEDGE_HOLD_MS;
	while (now_ms() < end) {
		assert_int_equal(sim_relay_service(f->r), 0);
		assert_int_equal(sim_relay_queued(f->r), 1);
		assert_int_equal(sim_relay_power(f->r), 1);
		poll(NULL, 0, 10);
	}
	assert_int_equal(sim_relay_set(f->r, 0), GL_ERR_RELAY);
	memset(chunk, 0x65, sizeof(chunk)); /* relay on, if ever read */
	while ((w = write(fd, chunk, sizeof(chunk))) > 0 && total < (1L << 20))
		total += w;
	assert_int_equal(w, -1); /* refused well before 1 MiB */
	assert_true(errno == EAGAIN || errno == EWOULDBLOCK);
	assert_int_equal(sim_relay_power(f->r), 1);

	assert_int_equal(
	    sim_relay_set_fault(f->r, SIM_RELAY_OK, err, sizeof(err)), 0);
	assert_int_equal(sim_relay_power(f->r), 0);
	assert_true(sim_relay_fd(f->r) >= 0);
	/* nothing of what was queued arrives afterwards */
	end = now_ms() + QUIET_MS;
	while (now_ms() < end) {
		assert_int_equal(sim_relay_service(f->r), 0);
		assert_int_equal(sim_relay_power(f->r), 0);
		poll(NULL, 0, 10);
	}
	assert_non_null(strstr(f->events,
			       "relay wedged (bytes not read)\n"
			       "relay discarded the bytes queued while wedged\n"
			       "relay off (board reset after wedge)\n"
			       "relay obeys again (relays off)\n"));
	assert_null(strstr(f->events, "(byte 0x6f)"));
	say(f, (const uint8_t[]){0x65}, 1);
	assert_int_equal(sim_relay_power(f->r), 1);
	close(fd);
}

/* The control port switches the relay directly. */
static void test_set_direct(void **state)
{
	struct fx *f = *state;

	assert_int_equal(sim_relay_set(f->r, 1), 0);
	assert_int_equal(sim_relay_power(f->r), 1);
	assert_int_equal(sim_relay_set(f->r, 0), 0);
	assert_int_equal(sim_relay_power(f->r), 0);
	assert_non_null(strstr(f->events, "relay on (control port)\n"
					  "relay off (control port)\n"));
}

/* ---- icstation ---------------------------------------------------------- */

static void test_icstation_handshake_and_states(void **state)
{
	struct fx *f = *state;

	say(f, (const uint8_t[]){0xFE}, 1); /* before the handshake */
	assert_int_equal(sim_relay_power(f->r), 0);
	say(f, (const uint8_t[]){0x50}, 1);
	expect_reply(f, (const uint8_t[]){0xAB}, 1);
	say(f, (const uint8_t[]){0xFE}, 1); /* still waiting for 0x51 */
	assert_int_equal(sim_relay_power(f->r), 0);
	say(f, (const uint8_t[]){0x51}, 1);
	say(f, (const uint8_t[]){0xFE}, 1); /* active low: relay 1 on */
	assert_int_equal(sim_relay_power(f->r), 1);
	say(f, (const uint8_t[]){0xFF}, 1);
	assert_int_equal(sim_relay_power(f->r), 0);
	/* a repeated handshake byte is a state byte: 0x50 has bit 0 clear */
	say(f, (const uint8_t[]){0x50}, 1);
	assert_int_equal(sim_relay_power(f->r), 1);
	expect_silence(f);
}

/* A replugged ICStation board needs its handshake again. */
static void test_icstation_replug_needs_handshake(void **state)
{
	struct fx *f = *state;
	char err[256];

	say(f, (const uint8_t[]){0x50, 0x51, 0xFE}, 3);
	expect_reply(f, (const uint8_t[]){0xAB}, 1);
	assert_int_equal(sim_relay_power(f->r), 1);
	close(f->fd);
	f->fd = -1;
	sim_relay_set_fault(f->r, SIM_RELAY_UNPLUG, err, sizeof(err));
	sim_relay_set_fault(f->r, SIM_RELAY_OK, err, sizeof(err));
	f->fd = open_host(f->link);
	assert_true(f->fd >= 0);
	say(f, (const uint8_t[]){0xFE}, 1);
	assert_int_equal(sim_relay_power(f->r), 0);
	say(f, (const uint8_t[]){0x50, 0x51, 0xFE}, 3);
	expect_reply(f, (const uint8_t[]){0xAB}, 1);
	assert_int_equal(sim_relay_power(f->r), 1);
}

/* ---- lcus, kmtronic ----------------------------------------------------- */

static void test_lcus_frames(void **state)
{
	struct fx *f = *state;

	say(f, (const uint8_t[]){0xA0, 0x01, 0x01, 0xA2}, 4);
	assert_int_equal(sim_relay_power(f->r), 1);
	say(f, (const uint8_t[]){0xA0, 0x01, 0x00, 0xA1}, 4);
	assert_int_equal(sim_relay_power(f->r), 0);
	/* bad checksum and another channel are ignored */
	say(f, (const uint8_t[]){0xA0, 0x01, 0x01, 0xA3}, 4);
	say(f, (const uint8_t[]){0xA0, 0x02, 0x01, 0xA3}, 4);
	assert_int_equal(sim_relay_power(f->r), 0);
	/* a frame split over two writes, after a stray byte */
	say(f, (const uint8_t[]){0x11, 0xA0, 0x01}, 3);
	say(f, (const uint8_t[]){0x01, 0xA2}, 2);
	assert_int_equal(sim_relay_power(f->r), 1);
	assert_non_null(strstr(f->events, "bad lcus frame"));
	expect_silence(f);
}

static void test_kmtronic_frames(void **state)
{
	struct fx *f = *state;

	say(f, (const uint8_t[]){0xFF, 0x01, 0x01}, 3);
	assert_int_equal(sim_relay_power(f->r), 1);
	say(f, (const uint8_t[]){0xFF, 0x01, 0x03}, 3);
	expect_reply(f, (const uint8_t[]){0xFF, 0x01, 0x01}, 3);
	say(f, (const uint8_t[]){0xFF, 0x01, 0x00}, 3);
	assert_int_equal(sim_relay_power(f->r), 0);
	say(f, (const uint8_t[]){0xFF, 0x01, 0x03}, 3);
	expect_reply(f, (const uint8_t[]){0xFF, 0x01, 0x00}, 3);
	say(f, (const uint8_t[]){0xFF, 0x02, 0x01}, 3); /* relay 2 */
	assert_int_equal(sim_relay_power(f->r), 0);
}

/* ---- decoder and link corner cases -------------------------------------- */

static void test_proto_names(void **state)
{
	enum sim_relay_proto p;

	(void)state;
	assert_int_equal(sim_relay_proto_parse("icstation", &p), 0);
	assert_int_equal(p, SIM_RELAY_ICSTATION);
	assert_string_equal(sim_relay_proto_name(SIM_RELAY_KMTRONIC),
			    "kmtronic");
	assert_int_equal(sim_relay_proto_parse("Devantech", &p), GL_ERR_ARG);
	assert_int_equal(sim_relay_proto_parse("numato", &p), GL_ERR_ARG);
}

/* Without a pty (the in-process simulator) the relay still works. */
static void test_no_pty(void **state)
{
	struct sim_relay *r;
	char err[128];

	(void)state;
	assert_int_equal(sim_relay_new(&r, SIM_RELAY_DEVANTECH, NULL, NULL), 0);
	assert_int_equal(sim_relay_fd(r), -1);
	assert_int_equal(sim_relay_service(r), 0);
	assert_int_equal(sim_relay_set(r, 1), 0);
	assert_int_equal(sim_relay_power(r), 1);
	assert_int_equal(
	    sim_relay_set_fault(r, SIM_RELAY_UNPLUG, err, sizeof(err)), 0);
	assert_int_equal(sim_relay_power(r), 0);
	assert_int_equal(sim_relay_set_fault(r, SIM_RELAY_OK, err, sizeof(err)),
			 0);
	assert_int_equal(sim_relay_power(r), 0);
	assert_int_equal(sim_relay_get_fault(r), SIM_RELAY_OK);
	sim_relay_free(r);
}

/* An existing symbolic link is replaced; a regular file is not. The link
 * is removed when the relay goes. */
static void test_link_rules(void **state)
{
	char dir[] = "/tmp/test_sim_relay.XXXXXX", path[96], want[160];
	char err[256], target[64];
	struct sim_relay *r;
	struct stat st;
	FILE *fp;

	(void)state;
	assert_non_null(mkdtemp(dir));
	snprintf(path, sizeof(path), "%s/link", dir);
	assert_int_equal(symlink("/dev/pts/stale", path), 0);
	assert_int_equal(sim_relay_new(&r, SIM_RELAY_LCUS, NULL, NULL), 0);
	assert_int_equal(sim_relay_attach(r, path, err, sizeof(err)), 0);
	assert_true(readlink(path, target, sizeof(target)) > 0);
	assert_memory_equal(target, "/dev/pts/", 9);
	sim_relay_free(r);
	assert_int_equal(lstat(path, &st), -1);

	fp = fopen(path, "w");
	assert_non_null(fp);
	fclose(fp);
	assert_int_equal(sim_relay_new(&r, SIM_RELAY_LCUS, NULL, NULL), 0);
	assert_int_equal(sim_relay_attach(r, path, err, sizeof(err)),
			 GL_ERR_SYS);
	snprintf(want, sizeof(want),
		 "refusing to replace '%s': not a "
		 "symbolic link",
		 path);
	assert_string_equal(err, want);
	sim_relay_free(r);
	assert_int_equal(stat(path, &st), 0); /* left alone */
	unlink(path);
	rmdir(dir);
}

#define T(name, proto)                                                         \
	cmocka_unit_test_setup_teardown(name, setup_##proto, teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_devantech_on_off_query, devantech),
	    T(test_devantech_unknown_byte_ignored, devantech),
	    T(test_unplug_and_replug, devantech),
	    T(test_writefail, devantech),
	    T(test_wedge, devantech),
	    T(test_set_direct, devantech),
	    T(test_icstation_handshake_and_states, icstation),
	    T(test_icstation_replug_needs_handshake, icstation),
	    T(test_lcus_frames, lcus),
	    T(test_kmtronic_frames, kmtronic),
	    cmocka_unit_test(test_proto_names),
	    cmocka_unit_test(test_no_pty),
	    cmocka_unit_test(test_link_rules),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
