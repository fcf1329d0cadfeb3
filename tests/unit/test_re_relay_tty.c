/*
 * test_re_relay_tty.c - the relay module over its POSIX tty back-end, on
 * real pseudo-terminal pairs made by this test (never a serial device).
 *
 * The test holds the master side (the "board") and a symbolic link to the
 * slave, as galil-sim's virtual relay does. Bytes on the wire are asserted
 * exactly per protocol; a fake board thread answers the ICStation handshake
 * and the Devantech state query where a test needs answers.
 *
 * Linked with --wrap=ioctl and --wrap=stat (test_re_relay_tty.ldflags):
 * ioctl(TIOCOUTQ) can be made to report bytes still queued (the pty driver
 * always reports 0: its bytes go straight to the master), and stat() calls
 * are counted (the cycle's check must not stat() the port every time).
 */
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <pty.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "base_clock.h"
#include "gl_err.h"
#include "re_relay.h"

#define WAIT_MS 2000 /* generous deadline for expected bytes */
#define LATE_MS 15   /* a timeout may come this much after its deadline */

/* ---- wrapped system calls ---- */

int __real_ioctl(int fd, unsigned long req, ...);
int __wrap_ioctl(int fd, unsigned long req, ...);
int __real_stat(const char *path, struct stat *st);
int __wrap_stat(const char *path, struct stat *st);

static int fake_outq = -1; /* >= 0: what TIOCOUTQ reports */
static int n_outq;	   /* TIOCOUTQ calls */
static int n_stat;	   /* stat() calls */

int __wrap_ioctl(int fd, unsigned long req, ...)
{
	va_list ap;
	void *arg;

	va_start(ap, req);
	arg = va_arg(ap, void *);
	va_end(ap);
	if (req == TIOCOUTQ) {
		n_outq++;
		if (fake_outq >= 0) {
			memcpy(arg, &fake_outq, sizeof(int));
			return 0;
		}
	}
	return __real_ioctl(fd, req, arg);
}

int __wrap_stat(const char *path, struct stat *st)
{
	n_stat++;
	return __real_stat(path, st);
}

/* ---- pseudo-terminal pairs ---- */

struct pty {
	int master;    /* the board's side */
	int slave;     /* kept open by the test: master never EIO */
	char name[64]; /* /dev/pts/N */
};

static void pty_open(struct pty *p)
{
	struct termios t;

	memset(&t, 0, sizeof(t));
	cfmakeraw(&t);
	assert_int_equal(openpty(&p->master, &p->slave, p->name, &t, NULL), 0);
	assert_int_equal(fcntl(p->master, F_SETFL, O_NONBLOCK), 0);
	assert_int_equal(fcntl(p->slave, F_SETFL, O_NONBLOCK), 0);
	assert_int_equal(strncmp(p->name, "/dev/pts/", 9), 0);
}

static void pty_close(struct pty *p)
{
	if (p->master >= 0)
		close(p->master);
	if (p->slave >= 0)
		close(p->slave);
	p->master = p->slave = -1;
}

static long now_ms(void)
{
	return (long)base_now_ms();
}

static int64_t mono_ns(void)
{
	return base_now_ns();
}

/* A timeout came at its deadline: not before, at most LATE_MS after. */
static void at_deadline(const char *what, int64_t t0, int deadline_ms)
{
	double ms = (double)(mono_ns() - t0) / 1e6;

	print_message("%s: timed out after %.2f ms (deadline %d ms)\n", what,
		      ms, deadline_ms);
	if (ms < deadline_ms || ms > deadline_ms + LATE_MS)
		fail_msg("%s: returned after %.2f ms, deadline %d ms", what, ms,
			 deadline_ms);
}

/* ---- the fake board (thread on the master side) ---- */

enum fake_kind { FAKE_DEVANTECH, FAKE_ICSTATION };

struct fake {
	pthread_t th;
	pthread_mutex_t mu;
	int master;
	enum fake_kind kind;
	bool running, stop;
	bool answer;	  /* devantech: answer 0x5B */
	uint8_t states;	  /* relay bits, 1 = energised */
	int stage;	  /* icstation: 0 id, 1 start, 2 run */
	uint8_t rx[4096]; /* every byte received */
	size_t nrx;
	int queries; /* 0x5B seen */
};

static void fake_byte(struct fake *f, uint8_t b)
{
	uint8_t reply;

	f->rx[f->nrx < sizeof(f->rx) ? f->nrx++ : f->nrx - 1] = b;
	if (f->kind == FAKE_ICSTATION) {
		if (f->stage == 0 && b == 0x50) {
			reply = 0xAB;
			f->stage = 1;
			(void)!write(f->master, &reply, 1);
		} else if (f->stage == 1 && b == 0x51) {
			f->stage = 2;
		} else if (f->stage == 2) {
			f->states = (uint8_t)~b;
		}
		return;
	}
	if (b >= 0x65 && b <= 0x6C)
		f->states |= (uint8_t)(1u << (b - 0x65));
	else if (b >= 0x6F && b <= 0x76)
		f->states &= (uint8_t) ~(1u << (b - 0x6F));
	else if (b == 0x5B) {
		f->queries++;
		if (f->answer)
			(void)!write(f->master, &f->states, 1);
	}
}

static void *fake_main(void *arg)
{
	struct fake *f = arg;
	struct pollfd p = {.fd = f->master, .events = POLLIN};
	uint8_t buf[64];
	ssize_t n, i;

	for (;;) {
		pthread_mutex_lock(&f->mu);
		if (f->stop) {
			pthread_mutex_unlock(&f->mu);
			return NULL;
		}
		pthread_mutex_unlock(&f->mu);
		if (poll(&p, 1, 5) <= 0)
			continue;
		n = read(f->master, buf, sizeof(buf));
		pthread_mutex_lock(&f->mu);
		for (i = 0; i < n; i++)
			fake_byte(f, buf[i]);
		pthread_mutex_unlock(&f->mu);
		if (n <= 0 && (p.revents & (POLLHUP | POLLERR)))
			usleep(1000);
	}
}

static void fake_start(struct fake *f, int master, enum fake_kind kind)
{
	memset(f, 0, sizeof(*f));
	pthread_mutex_init(&f->mu, NULL);
	f->master = master;
	f->kind = kind;
	f->answer = true;
	assert_int_equal(pthread_create(&f->th, NULL, fake_main, f), 0);
	f->running = true;
}

static void fake_stop(struct fake *f)
{
	if (!f->running)
		return;
	pthread_mutex_lock(&f->mu);
	f->stop = true;
	pthread_mutex_unlock(&f->mu);
	pthread_join(f->th, NULL);
	pthread_mutex_destroy(&f->mu);
	f->running = false;
}

/* Wait (deadline WAIT_MS) until the fake has received @n bytes; copy them
 * and forget them. Asserts exactly @n arrived. */
static void fake_expect(struct fake *f, const uint8_t *want, size_t n)
{
	long end = now_ms() + WAIT_MS;
	size_t got;

	for (;;) {
		pthread_mutex_lock(&f->mu);
		got = f->nrx;
		pthread_mutex_unlock(&f->mu);
		if (got >= n || now_ms() > end)
			break;
		usleep(1000);
	}
	pthread_mutex_lock(&f->mu);
	assert_int_equal(f->nrx, n);
	assert_memory_equal(f->rx, want, n);
	f->nrx = 0;
	pthread_mutex_unlock(&f->mu);
}

/* ---- fixture ---- */

struct fix {
	char dir[64];
	char link[128];	 /* dir/relay -> /dev/pts/N */
	char state[128]; /* dir/ics.state */
	struct pty pty;
	struct fake fake;
	struct re_relay_cfg cfg;
};

static void fix_link(struct fix *f, const char *target)
{
	char tmp[160];

	snprintf(tmp, sizeof(tmp), "%s.new", f->link);
	assert_int_equal(symlink(target, tmp), 0);
	assert_int_equal(rename(tmp, f->link), 0);
}

static int setup(void **state)
{
	struct fix *f = calloc(1, sizeof(*f));

	assert_non_null(f);
	strcpy(f->dir, "/tmp/h4relay.XXXXXX");
	assert_non_null(mkdtemp(f->dir));
	snprintf(f->link, sizeof(f->link), "%s/relay", f->dir);
	snprintf(f->state, sizeof(f->state), "%s/ics.state", f->dir);
	pty_open(&f->pty);
	fix_link(f, f->pty.name);
	snprintf(f->cfg.port, sizeof(f->cfg.port), "%s", f->link);
	f->cfg.proto = RE_RELAY_DEVANTECH;
	f->cfg.channel = 1;
	f->cfg.backend = RE_RELAY_BACKEND_AUTO;
	f->cfg.baud = 9600;
	f->cfg.write_timeout_ms = 100;
	f->cfg.off_deadline_ms = 200;
	f->cfg.readback_timeout_ms = 200;
	snprintf(f->cfg.icstation_state, sizeof(f->cfg.icstation_state), "%s",
		 f->state);
	*state = f;
	return 0;
}

static int teardown(void **state)
{
	struct fix *f = *state;

	fake_outq = -1;
	fake_stop(&f->fake);
	pty_close(&f->pty);
	unlink(f->link);
	unlink(f->state);
	rmdir(f->dir);
	free(f);
	return 0;
}

/* Read exactly @n bytes from the master (deadline WAIT_MS), then assert
 * nothing more is waiting (writes are complete when the call returns). */
static void wire_expect(int master, const uint8_t *want, size_t n)
{
	struct pollfd p = {.fd = master, .events = POLLIN};
	uint8_t buf[256];
	long end = now_ms() + WAIT_MS;
	size_t got = 0;
	ssize_t r;

	while (got < n && now_ms() < end) {
		if (poll(&p, 1, 10) <= 0)
			continue;
		r = read(master, buf + got, sizeof(buf) - got);
		if (r > 0)
			got += (size_t)r;
	}
	r = read(master, buf + got, sizeof(buf) - got);
	if (r > 0)
		got += (size_t)r;
	assert_int_equal(got, n);
	assert_memory_equal(buf, want, n);
}

static void wire_none(int master)
{
	uint8_t b;

	assert_int_equal(read(master, &b, 1), -1);
	assert_int_equal(errno, EAGAIN);
}

/* re_relay_open() that must succeed; shows the reason if not. */
static void open_ok(struct fix *f, re_relay **r)
{
	char err[RE_RELAY_ERR_MAX];

	if (re_relay_open(r, &f->cfg, err, sizeof(err)) != GL_OK)
		fail_msg("re_relay_open: %s", err);
	assert_string_equal(err, "");
}

/* ---- tests ---- */

/* Devantech relay 1: off at open, on, check writes nothing, off, close. */
static void test_devantech_bytes(void **state)
{
	struct fix *f = *state;
	static const uint8_t off[] = {0x6F}, on[] = {0x65};
	re_relay *r;
	char err[RE_RELAY_ERR_MAX];

	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)), GL_OK);
	assert_string_equal(re_relay_backend_name(r), "tty");
	assert_int_equal(re_relay_state(r), RE_RELAY_OFF);
	wire_expect(f->pty.master, off, 1);
	assert_int_equal(re_relay_on(r), GL_OK);
	assert_int_equal(re_relay_state(r), RE_RELAY_ON);
	wire_expect(f->pty.master, on, 1);
	assert_int_equal(re_relay_check(r), GL_OK);
	assert_int_equal(re_relay_check(r), GL_OK);
	wire_none(f->pty.master);
	assert_int_equal(re_relay_off(r), GL_OK);
	assert_int_equal(re_relay_state(r), RE_RELAY_OFF);
	wire_expect(f->pty.master, off, 1);
	assert_int_equal(re_relay_close(r), GL_OK);
	wire_expect(f->pty.master, off, 1);
}

/* open + on + close for one protocol: off, on, off on the wire. */
static void proto_case(struct fix *f, enum re_relay_proto proto, int ch,
		       const uint8_t *on, const uint8_t *off, size_t n)
{
	re_relay *r;
	char err[RE_RELAY_ERR_MAX];

	f->cfg.proto = proto;
	f->cfg.channel = ch;
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)), GL_OK);
	wire_expect(f->pty.master, off, n);
	assert_int_equal(re_relay_on(r), GL_OK);
	wire_expect(f->pty.master, on, n);
	assert_int_equal(re_relay_close(r), GL_OK);
	wire_expect(f->pty.master, off, n);
}

static void test_protocol_bytes(void **state)
{
	static const uint8_t dv_on[] = {0x6C}, dv_off[] = {0x76};
	static const uint8_t lc_on[] = {0xA0, 0x01, 0x01, 0xA2};
	static const uint8_t lc_off[] = {0xA0, 0x01, 0x00, 0xA1};
	static const uint8_t lc2_on[] = {0xA0, 0x02, 0x01, 0xA3};
	static const uint8_t lc2_off[] = {0xA0, 0x02, 0x00, 0xA2};
	static const uint8_t km_on[] = {0xFF, 0x01, 0x01};
	static const uint8_t km_off[] = {0xFF, 0x01, 0x00};
	static const uint8_t km3_on[] = {0xFF, 0x03, 0x01};
	static const uint8_t km3_off[] = {0xFF, 0x03, 0x00};
	static const uint8_t ex_on[] = {0x01, 0x02, 0x03};
	static const uint8_t ex_off[] = {0x04, 0x05, 0x06};
	struct fix *f = *state;

	proto_case(f, RE_RELAY_DEVANTECH, 8, dv_on, dv_off, 1);
	proto_case(f, RE_RELAY_LCUS, 1, lc_on, lc_off, 4);
	proto_case(f, RE_RELAY_LCUS, 2, lc2_on, lc2_off, 4);
	proto_case(f, RE_RELAY_KMTRONIC, 1, km_on, km_off, 3);
	proto_case(f, RE_RELAY_KMTRONIC, 3, km3_on, km3_off, 3);
	memcpy(f->cfg.on, ex_on, 3);
	memcpy(f->cfg.off, ex_off, 3);
	f->cfg.on_len = f->cfg.off_len = 3;
	proto_case(f, RE_RELAY_EXPLICIT, 1, ex_on, ex_off, 3);
}

/* The pure message table, including ICStation masks and bad channels. */
static void test_messages(void **state)
{
	struct re_relay_cfg c;
	uint8_t b[RE_RELAY_CODE_MAX];

	(void)state;
	memset(&c, 0, sizeof(c));
	c.proto = RE_RELAY_ICSTATION;
	c.channel = 1;
	assert_int_equal(re_relay_message(&c, true, b), 1);
	assert_int_equal(b[0], 0xFE);
	assert_int_equal(re_relay_message(&c, false, b), 1);
	assert_int_equal(b[0], 0xFF);
	c.channel = 4;
	assert_int_equal(re_relay_message(&c, true, b), 1);
	assert_int_equal(b[0], 0xF7);
	c.proto = RE_RELAY_DEVANTECH;
	c.channel = 2;
	assert_int_equal(re_relay_message(&c, true, b), 1);
	assert_int_equal(b[0], 0x66);
	assert_int_equal(re_relay_message(&c, false, b), 1);
	assert_int_equal(b[0], 0x70);
	c.channel = 0;
	assert_int_equal(re_relay_message(&c, true, b), GL_ERR_ARG);
	c.channel = 9;
	assert_int_equal(re_relay_message(&c, false, b), GL_ERR_ARG);
	c.proto = RE_RELAY_EXPLICIT;
	c.on_len = 0;
	assert_int_equal(re_relay_message(&c, true, b), GL_ERR_ARG);
	assert_string_equal(re_relay_proto_name(RE_RELAY_KMTRONIC), "kmtronic");
}

/* ICStation: handshake at the first open only; again after a re-plug. */
static void test_icstation_handshake_once(void **state)
{
	static const uint8_t first[] = {0x50, 0x51, 0xFF};
	static const uint8_t on[] = {0xFE}, off[] = {0xFF};
	struct fix *f = *state;
	struct pty old;
	re_relay *r;
	char err[RE_RELAY_ERR_MAX], line[256];
	FILE *sf;

	f->cfg.proto = RE_RELAY_ICSTATION;
	fake_start(&f->fake, f->pty.master, FAKE_ICSTATION);
	open_ok(f, &r);
	fake_expect(&f->fake, first, 3);
	assert_int_equal(re_relay_on(r), GL_OK);
	fake_expect(&f->fake, on, 1);
	assert_int_equal(re_relay_close(r), GL_OK);
	fake_expect(&f->fake, off, 1);
	sf = fopen(f->state, "r");
	assert_non_null(sf);
	assert_non_null(fgets(line, sizeof(line), sf));
	fclose(sf);
	assert_int_equal(strncmp(line, "icstation rdev=", 15), 0);
	assert_non_null(strstr(line, " model=0xAB\n"));
	/* Reopen: the same board power-up, no handshake, just "off". */
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)), GL_OK);
	fake_expect(&f->fake, off, 1);
	assert_int_equal(re_relay_close(r), GL_OK);
	fake_expect(&f->fake, off, 1);
	/* Re-plug: a new device node, so the handshake again. */
	fake_stop(&f->fake);
	old = f->pty;
	pty_open(&f->pty);
	pty_close(&old);
	fix_link(f, f->pty.name);
	fake_start(&f->fake, f->pty.master, FAKE_ICSTATION);
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)), GL_OK);
	fake_expect(&f->fake, first, 3);
	assert_int_equal(re_relay_close(r), GL_OK);
	fake_expect(&f->fake, off, 1);
}

/* ICStation that does not answer 0x50: all off at once, refused. */
static void test_icstation_no_answer(void **state)
{
	static const uint8_t wire[] = {0x50, 0xFF};
	struct fix *f = *state;
	re_relay *r = (re_relay *)&r;
	char err[RE_RELAY_ERR_MAX], want[RE_RELAY_ERR_MAX];
	struct stat st;

	f->cfg.proto = RE_RELAY_ICSTATION;
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)),
			 GL_ERR_RELAY);
	assert_null(r);
	snprintf(want, sizeof(want),
		 "relay '%s': no answer to the icstation "
		 "handshake within 500 ms (board already initialised?): "
		 "unplug and re-plug the relay",
		 f->link);
	assert_string_equal(err, want);
	wire_expect(f->pty.master, wire, 2);
	assert_int_equal(stat(f->state, &st), -1);
}

/* The far end goes away: check fails, off fails with EIO, reopen ENOENT. */
static void test_far_end_closed(void **state)
{
	struct fix *f = *state;
	re_relay *r;
	char err[RE_RELAY_ERR_MAX], want[RE_RELAY_ERR_MAX];

	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)), GL_OK);
	assert_int_equal(re_relay_on(r), GL_OK);
	assert_int_equal(re_relay_check(r), GL_OK);
	pty_close(&f->pty); /* board unplugged: node and link gone */
	unlink(f->link);
	assert_int_equal(re_relay_check(r), GL_ERR_RELAY);
	snprintf(want, sizeof(want), "relay '%s': link lost (hang-up)",
		 f->link);
	assert_string_equal(re_relay_errmsg(r), want);
	assert_int_equal(re_relay_off(r), GL_ERR_RELAY);
	snprintf(want, sizeof(want),
		 "relay '%s': write failed: Input/output "
		 "error; reopen: cannot open: No such file or directory",
		 f->link);
	assert_string_equal(re_relay_errmsg(r), want);
	assert_int_equal(re_relay_state(r), RE_RELAY_UNKNOWN);
	/* Still refuses to claim anything; on is refused too. */
	assert_int_equal(re_relay_on(r), GL_ERR_RELAY);
	assert_int_equal(re_relay_state(r), RE_RELAY_UNKNOWN);
	assert_int_equal(re_relay_close(r), GL_ERR_RELAY);
}

/*
 * The board goes away and its pty number is reused by someone else (the
 * link now names an unrelated terminal): "off" is not sent there.
 */
static void test_pty_number_reused(void **state)
{
	static const uint8_t off[] = {0x6F};
	struct fix *f = *state;
	struct pty other;
	re_relay *r;
	char want[RE_RELAY_ERR_MAX];

	open_ok(f, &r);
	wire_expect(f->pty.master, off, 1);
	assert_int_equal(re_relay_on(r), GL_OK);
	pty_close(&f->pty);
	pty_open(&other);
	fix_link(f, other.name);
	assert_int_equal(re_relay_check(r), GL_ERR_RELAY);
	assert_int_equal(re_relay_off(r), GL_ERR_RELAY);
	snprintf(want, sizeof(want),
		 "relay '%s': write failed: Input/output error; reopen: the "
		 "port now names another device",
		 f->link);
	assert_string_equal(re_relay_errmsg(r), want);
	assert_int_equal(re_relay_state(r), RE_RELAY_UNKNOWN);
	assert_int_equal(re_relay_close(r), GL_ERR_RELAY);
	wire_none(other.master); /* nothing reached the stranger */
	pty_close(&other);
}

/* The link now names another pty: check fails, on refused, none written. */
static void test_node_replaced(void **state)
{
	struct fix *f = *state;
	struct pty other;
	re_relay *r;
	char err[RE_RELAY_ERR_MAX], want[RE_RELAY_ERR_MAX];
	static const uint8_t off[] = {0x6F};

	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)), GL_OK);
	wire_expect(f->pty.master, off, 1);
	pty_open(&other);
	fix_link(f, other.name);
	assert_int_equal(re_relay_check(r), GL_ERR_RELAY);
	snprintf(want, sizeof(want),
		 "relay '%s': the port now names another "
		 "device",
		 f->link);
	assert_string_equal(re_relay_errmsg(r), want);
	assert_int_equal(re_relay_on(r), GL_ERR_RELAY);
	wire_none(f->pty.master);
	wire_none(other.master);
	/* Off still goes to the open descriptor (the original relay). */
	assert_int_equal(re_relay_off(r), GL_OK);
	wire_expect(f->pty.master, off, 1);
	wire_none(other.master);
	re_relay_close(r);
	pty_close(&other);
}

/* Fill the pty (board not reading) until it stays full for 50 ms. */
static void pty_fill(int slave)
{
	struct pollfd p = {.fd = slave, .events = POLLOUT};
	uint8_t junk[4096];
	long end = now_ms() + WAIT_MS;

	memset(junk, 0x55, sizeof(junk));
	while (now_ms() < end) {
		if (write(slave, junk, sizeof(junk)) > 0)
			continue;
		assert_int_equal(errno, EAGAIN);
		while (write(slave, junk, 1) > 0)
			; /* the last bytes, one at a time */
		if (poll(&p, 1, 50) == 0)
			return;
	}
	fail_msg("pty never filled up");
}

/* The board reads again: take everything it was sent until the line has
 * been quiet for 50 ms (bytes reach the master in bursts); return whether
 * @b was among them. */
static bool board_drain(int master, uint8_t b)
{
	struct pollfd p = {.fd = master, .events = POLLIN};
	uint8_t buf[4096];
	long end = now_ms() + WAIT_MS;
	bool seen = false;
	ssize_t n, i;

	while (now_ms() < end) {
		n = read(master, buf, sizeof(buf));
		for (i = 0; i < n; i++)
			seen = seen || buf[i] == b;
		if (n > 0)
			continue;
		if (poll(&p, 1, 50) == 0)
			return seen;
	}
	fail_msg("the pty never went quiet");
	return seen;
}

/* A board that stops reading: "on" is not accepted and times out at its
 * deadline, never to be written later; "off" works once it reads again. */
static void test_write_timeout(void **state)
{
	static const uint8_t off[] = {0x6F};
	struct fix *f = *state;
	re_relay *r;
	char want[RE_RELAY_ERR_MAX];
	int64_t t0;

	f->cfg.write_timeout_ms = 30;
	open_ok(f, &r);
	wire_expect(f->pty.master, off, 1);
	pty_fill(f->pty.slave);
	t0 = mono_ns();
	assert_int_equal(re_relay_on(r), GL_ERR_TIMEOUT);
	at_deadline("on, pty full", t0, 30);
	snprintf(want, sizeof(want),
		 "relay '%s': on not confirmed: only 0 of 1 bytes accepted by "
		 "the driver within 30 ms",
		 f->link);
	assert_string_equal(re_relay_errmsg(r), want);
	assert_int_equal(re_relay_state(r), RE_RELAY_UNKNOWN);
	assert_false(board_drain(f->pty.master, 0x65)); /* never "on" */
	assert_int_equal(re_relay_off(r), GL_OK);
	assert_int_equal(re_relay_state(r), RE_RELAY_OFF);
	wire_expect(f->pty.master, off, 1);
	assert_int_equal(re_relay_close(r), GL_OK);
}

/* A pty whose master nobody reads (buffer full): "off" returns the
 * timeout at its deadline; the state is not "off"; once the board reads
 * again, "off" is confirmed. */
static void test_off_pty_full(void **state)
{
	static const uint8_t off[] = {0x6F}, on[] = {0x65};
	struct fix *f = *state;
	re_relay *r;
	char want[RE_RELAY_ERR_MAX];
	int64_t t0;

	f->cfg.off_deadline_ms = 20;
	open_ok(f, &r);
	wire_expect(f->pty.master, off, 1);
	assert_int_equal(re_relay_on(r), GL_OK);
	wire_expect(f->pty.master, on, 1);
	pty_fill(f->pty.slave);
	t0 = mono_ns();
	assert_int_equal(re_relay_off(r), GL_ERR_TIMEOUT);
	at_deadline("off, pty full", t0, 20);
	snprintf(want, sizeof(want),
		 "relay '%s': off not confirmed: only 0 of 1 bytes accepted "
		 "by the driver within 20 ms",
		 f->link);
	assert_string_equal(re_relay_errmsg(r), want);
	assert_int_equal(re_relay_state(r), RE_RELAY_UNKNOWN);
	t0 = mono_ns();
	assert_int_equal(re_relay_off_start(r), GL_OK);
	assert_true(mono_ns() - t0 < 5000000); /* start never waits */
	assert_int_equal(re_relay_off_finish(r, 20), GL_ERR_TIMEOUT);
	at_deadline("off split, pty full", t0, 20);
	board_drain(f->pty.master, 0);
	assert_int_equal(re_relay_off(r), GL_OK);
	assert_int_equal(re_relay_state(r), RE_RELAY_OFF);
	wire_expect(f->pty.master, off, 1);
	assert_int_equal(re_relay_close(r), GL_OK);
}

/* A byte that stays in the output queue (TIOCOUTQ reports 1; simulated,
 * the pty driver always reports 0): "off" times out at its deadline; the
 * byte itself was handed over. Close discards the queue, without waiting
 * beyond its own deadline. */
static void test_off_byte_queued(void **state)
{
	static const uint8_t off[] = {0x6F}, on[] = {0x65};
	struct fix *f = *state;
	re_relay *r;
	char want[RE_RELAY_ERR_MAX];
	int64_t t0;

	f->cfg.off_deadline_ms = 20;
	open_ok(f, &r);
	wire_expect(f->pty.master, off, 1);
	assert_int_equal(re_relay_on(r), GL_OK);
	wire_expect(f->pty.master, on, 1);
	fake_outq = 1;
	n_outq = 0;
	t0 = mono_ns();
	assert_int_equal(re_relay_off(r), GL_ERR_TIMEOUT);
	at_deadline("off, byte queued", t0, 20);
	assert_true(n_outq >= 10); /* polled about every ms */
	snprintf(want, sizeof(want),
		 "relay '%s': off not confirmed: 1 byte still queued after "
		 "20 ms",
		 f->link);
	assert_string_equal(re_relay_errmsg(r), want);
	assert_int_equal(re_relay_state(r), RE_RELAY_UNKNOWN);
	wire_expect(f->pty.master, off, 1);
	t0 = mono_ns();
	assert_int_equal(re_relay_close(r), GL_ERR_TIMEOUT);
	at_deadline("close, byte queued", t0, 20);
	fake_outq = -1;
}

/* A healthy relay confirms at once: without read-back, and with the
 * Devantech read-back answered by the board. */
static void test_off_confirms_quickly(void **state)
{
	struct fix *f = *state;
	re_relay *r;
	double ms_plain, ms_rb;
	int64_t t0;

	open_ok(f, &r);
	t0 = mono_ns();
	assert_int_equal(re_relay_off(r), GL_OK);
	ms_plain = (double)(mono_ns() - t0) / 1e6;
	assert_int_equal(re_relay_close(r), GL_OK);
	f->cfg.readback = true;
	fake_start(&f->fake, f->pty.master, FAKE_DEVANTECH);
	open_ok(f, &r);
	assert_int_equal(re_relay_on(r), GL_OK);
	t0 = mono_ns();
	assert_int_equal(re_relay_off(r), GL_OK);
	ms_rb = (double)(mono_ns() - t0) / 1e6;
	assert_int_equal(re_relay_state(r), RE_RELAY_OFF);
	print_message("off confirmed in %.3f ms (tty), %.3f ms with the "
		      "read-back\n",
		      ms_plain, ms_rb);
	assert_true(ms_plain < 5.0);
	assert_true(ms_rb < 50.0); /* a thread on a busy 2-core machine */
	assert_int_equal(re_relay_close(r), GL_OK);
}

/* Devantech read-back: agreeing board passes; a dropped relay or a silent
 * board fails the check within the deadline. */
static void test_readback(void **state)
{
	struct fix *f = *state;
	re_relay *r;
	char err[RE_RELAY_ERR_MAX], want[RE_RELAY_ERR_MAX];
	long end, t0;
	int rc = GL_OK, q;

	f->cfg.readback = true;
	fake_start(&f->fake, f->pty.master, FAKE_DEVANTECH);
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)), GL_OK);
	assert_int_equal(re_relay_on(r), GL_OK);
	for (end = now_ms() + 300; now_ms() < end;) {
		assert_int_equal(re_relay_check(r), GL_OK);
		usleep(2000);
	}
	pthread_mutex_lock(&f->fake.mu);
	q = f->fake.queries;
	assert_int_equal(f->fake.states, 0x01);
	f->fake.states = 0; /* the board reset: relay dropped */
	pthread_mutex_unlock(&f->fake.mu);
	assert_true(q >= 2);
	for (end = now_ms() + WAIT_MS; rc == GL_OK && now_ms() < end;) {
		rc = re_relay_check(r);
		usleep(2000);
	}
	assert_int_equal(rc, GL_ERR_RELAY);
	snprintf(want, sizeof(want),
		 "relay '%s': read-back shows channel 1 "
		 "off, expected on",
		 f->link);
	assert_string_equal(re_relay_errmsg(r), want);
	/* A silent board: no answer within readback_timeout_ms (200). */
	assert_int_equal(re_relay_off(r), GL_OK);
	pthread_mutex_lock(&f->fake.mu);
	f->fake.answer = false;
	pthread_mutex_unlock(&f->fake.mu);
	t0 = now_ms();
	for (rc = GL_OK, end = t0 + WAIT_MS; rc == GL_OK && now_ms() < end;) {
		rc = re_relay_check(r);
		usleep(2000);
	}
	assert_int_equal(rc, GL_ERR_RELAY);
	assert_true(now_ms() - t0 >= 200);
	snprintf(want, sizeof(want),
		 "relay '%s': no answer to the state "
		 "query (0x5B) within 200 ms",
		 f->link);
	assert_string_equal(re_relay_errmsg(r), want);
	re_relay_close(r);
}

/* re_relay_check() does not block: measured over 2000 calls. */
static void test_check_nonblocking(void **state)
{
	struct fix *f = *state;
	int64_t a, b;
	re_relay *r;
	char err[RE_RELAY_ERR_MAX];
	double us, worst = 0, total = 0;
	int i;

	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)), GL_OK);
	for (i = 0; i < 2000; i++) {
		a = base_now_ns();
		assert_int_equal(re_relay_check(r), GL_OK);
		b = base_now_ns();
		us = (double)(b - a) / 1e3;
		total += us;
		if (us > worst)
			worst = us;
	}
	printf("re_relay_check (tty): mean %.1f us, worst %.1f us\n",
	       total / 2000, worst);
	assert_true(worst < 20000.0); /* generous: noisy 2-core machine */
	re_relay_close(r);
}

/* Wait (deadline WAIT_MS) until the coarse clock that stamps inode change
 * times has passed @path's change time, so that a change is visible. */
static void ctime_passes(const char *path)
{
	struct timespec now;
	struct stat st;
	long end = now_ms() + WAIT_MS;

	assert_int_equal(__real_stat(path, &st), 0);
	while (now_ms() < end) {
		clock_gettime(CLOCK_REALTIME_COARSE, &now);
		if (now.tv_sec > st.st_ctim.tv_sec ||
		    (now.tv_sec == st.st_ctim.tv_sec &&
		     now.tv_nsec > st.st_ctim.tv_nsec))
			return;
		usleep(500);
	}
	fail_msg("the clock never passed the change time of '%s'", path);
}

/*
 * The cycle's check does not stat() the port path every call: inotify
 * says when to (at most one stat() a second otherwise). A change of the
 * node (chmod: new change time) is still seen at the next check, and the
 * check keeps failing (by stat() in every call) while it lasts.
 */
static void test_check_stat_on_event(void **state)
{
	struct fix *f = *state;
	re_relay *r;
	char want[RE_RELAY_ERR_MAX];
	long t0;
	int i;

	open_ok(f, &r);
	assert_int_equal(re_relay_check(r), GL_OK); /* the first one stat()s */
	n_stat = 0;
	t0 = now_ms();
	for (i = 0; i < 1000; i++)
		assert_int_equal(re_relay_check(r), GL_OK);
	print_message("1000 checks in %ld ms: %d stat() calls\n", now_ms() - t0,
		      n_stat);
	assert_true(n_stat <= (now_ms() - t0) / 1000 + 1);
	ctime_passes(f->pty.name);
	assert_int_equal(chmod(f->pty.name, 0600), 0);
	n_stat = 0;
	assert_int_equal(re_relay_check(r), GL_ERR_RELAY);
	snprintf(want, sizeof(want),
		 "relay '%s': the port now names another device", f->link);
	assert_string_equal(re_relay_errmsg(r), want);
	assert_int_equal(n_stat, 1);
	assert_int_equal(re_relay_check(r), GL_ERR_RELAY);
	assert_int_equal(n_stat, 2);
	assert_string_equal(re_relay_errmsg(r), want);
	re_relay_close(r);
}

/* re_relay_check_seen(): the caller's own poll of re_relay_fds() (the
 * supervisor's one look per cycle). Nothing seen: no stat();
 * the watch's event: the events read and the node stat()ed (a changed
 * mode refused); a hang-up or an invalid descriptor seen: refused. */
static void test_check_seen(void **state)
{
	struct fix *f = *state;
	struct pollfd p[2];
	char want[RE_RELAY_ERR_MAX];
	re_relay *r;
	int fd, wfd;

	open_ok(f, &r);
	re_relay_fds(r, &fd, &wfd);
	assert_true(fd >= 0 && wfd >= 0 && fd != wfd);
	assert_int_equal(re_relay_check(r), GL_OK); /* the first one stat()s */
	n_stat = 0;
	for (int i = 0; i < 100; i++)
		assert_int_equal(re_relay_check_seen(r, 0, 0), GL_OK);
	assert_int_equal(n_stat, 0);
	ctime_passes(f->pty.name);
	assert_int_equal(chmod(f->pty.name, 0600), 0);
	p[0] = (struct pollfd){.fd = fd, .events = 0};
	p[1] = (struct pollfd){.fd = wfd, .events = POLLIN};
	assert_int_equal(poll(p, 2, 1000), 1);
	assert_int_equal(p[1].revents, POLLIN);
	assert_int_equal(re_relay_check_seen(r, p[0].revents, p[1].revents),
			 GL_ERR_RELAY);
	assert_int_equal(n_stat, 1);
	snprintf(want, sizeof(want),
		 "relay '%s': the port now names another device", f->link);
	assert_string_equal(re_relay_errmsg(r), want);
	re_relay_close(r);

	open_ok(f, &r);
	assert_int_equal(re_relay_check_seen(r, POLLHUP, 0), GL_ERR_RELAY);
	snprintf(want, sizeof(want), "relay '%s': link lost (hang-up)",
		 f->link);
	assert_string_equal(re_relay_errmsg(r), want);
	assert_int_equal(re_relay_check_seen(r, POLLNVAL, 0), GL_ERR_RELAY);
	snprintf(want, sizeof(want),
		 "relay '%s': descriptor lost: Bad file descriptor", f->link);
	assert_string_equal(re_relay_errmsg(r), want);
	re_relay_close(r);
	re_relay_fds(NULL, &fd, &wfd);
	assert_int_equal(fd, -1);
	assert_int_equal(wfd, -1);
}

/*
 * A directory above the watched ones renamed (dir/sub/relay -> the path
 * no longer exists, no inotify event reaches the watches on dir/sub and
 * /dev/pts): the once-a-second stat() finds it within 1 s.
 */
static void test_check_ancestor_moved(void **state)
{
	struct fix *f = *state;
	char sub[160], link[192], moved[96], want[RE_RELAY_ERR_MAX];
	re_relay *r;
	long t0, t1, end;
	int rc = GL_OK;

	snprintf(sub, sizeof(sub), "%s/sub", f->dir);
	snprintf(link, sizeof(link), "%s/relay", sub);
	snprintf(moved, sizeof(moved), "%s.moved", f->dir);
	assert_int_equal(mkdir(sub, 0700), 0);
	assert_int_equal(symlink(f->pty.name, link), 0);
	snprintf(f->cfg.port, sizeof(f->cfg.port), "%s", link);
	open_ok(f, &r);
	assert_int_equal(re_relay_check(r), GL_OK);
	t0 = now_ms();
	assert_int_equal(rename(f->dir, moved), 0);
	for (end = t0 + WAIT_MS; rc == GL_OK && now_ms() < end;) {
		rc = re_relay_check(r);
		usleep(1000);
	}
	t1 = now_ms();
	assert_int_equal(rename(moved, f->dir), 0);
	print_message("ancestor renamed: seen after %ld ms\n", t1 - t0);
	assert_int_equal(rc, GL_ERR_RELAY);
	snprintf(want, sizeof(want),
		 "relay '%s': device node is gone: No such file or directory",
		 link);
	assert_string_equal(re_relay_errmsg(r), want);
	assert_true(t1 - t0 <= 1000 + 100); /* + a loop step, scheduling */
	re_relay_close(r);
	unlink(link);
	rmdir(sub);
}

/* Clinical mode never uses the tty back-end, even for a pty path. */
static void test_clinical_refuses_tty(void **state)
{
	struct fix *f = *state;
	re_relay *r;
	char err[RE_RELAY_ERR_MAX], want[RE_RELAY_ERR_MAX];

	f->cfg.clinical = true;
	f->cfg.backend = RE_RELAY_BACKEND_TTY;
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)),
			 GL_ERR_ARG);
	snprintf(want, sizeof(want),
		 "relay '%s': the tty back-end is not "
		 "allowed in clinical mode",
		 f->link);
	assert_string_equal(err, want);
	/* auto in clinical mode: libserialport, which refuses a pty. */
	f->cfg.backend = RE_RELAY_BACKEND_AUTO;
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)),
			 GL_ERR_RELAY);
	snprintf(want, sizeof(want),
		 "relay '%s': cannot open: not a serial "
		 "port known to libserialport",
		 f->link);
	assert_string_equal(err, want);
	wire_none(f->pty.master);
}

/* A missing port says so plainly. */
static void test_missing_port(void **state)
{
	struct fix *f = *state;
	re_relay *r;
	char err[RE_RELAY_ERR_MAX], want[RE_RELAY_ERR_MAX];

	snprintf(f->cfg.port, sizeof(f->cfg.port), "%s/none", f->dir);
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)),
			 GL_ERR_RELAY);
	snprintf(want, sizeof(want),
		 "relay '%s/none': cannot open: No such "
		 "file or directory",
		 f->dir);
	assert_string_equal(err, want);
	f->cfg.port[0] = '\0';
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)),
			 GL_ERR_ARG);
	assert_string_equal(err, "relay '': no port configured");
	assert_int_equal(re_relay_close(NULL), GL_OK);
}

int main(void)
{
	static const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_devantech_bytes, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_protocol_bytes, setup,
					    teardown),
	    cmocka_unit_test(test_messages),
	    cmocka_unit_test_setup_teardown(test_icstation_handshake_once,
					    setup, teardown),
	    cmocka_unit_test_setup_teardown(test_icstation_no_answer, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_far_end_closed, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_pty_number_reused, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_node_replaced, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_write_timeout, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_off_pty_full, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_off_byte_queued, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_off_confirms_quickly, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_readback, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_check_nonblocking, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_check_stat_on_event, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_check_seen, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_check_ancestor_moved, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_clinical_refuses_tty, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_missing_port, setup, teardown),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
