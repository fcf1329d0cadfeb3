/*
 * test_re_relay.c - the relay module over its libserialport back-end, with
 * every sp_* call replaced through the linker's --wrap
 * (test_re_relay.ldflags). No serial device is ever opened: the fake port
 * hands out the slave of a pseudo-terminal made here as its descriptor, so
 * the link checks (poll, fstat, stat) run on something real and harmless.
 *
 * Covered: open / configure / write / short write / drain failures, the
 * "off" retry through a reopen, the link checks, the Devantech read-back
 * and the ICStation handshake, with the exact bytes written and the exact
 * messages.
 */
#include <errno.h>
#include <fcntl.h>
#include <libserialport.h>
#include <pty.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
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
#include "re_relay.h"

/* ---- the fake libserialport ---- */

static char fake_port_storage;
#define FAKE_PORT ((struct sp_port *)&fake_port_storage)

/*
 * The fake port holds what a USB-serial driver holds: bytes accepted by
 * sp_nonblocking_write go to the board at once (wire[], where a Devantech
 * or ICStation board model answers) unless the adapter is wedged; then
 * they wait in q[], which sp_output_waiting reports and sp_flush drops.
 */
struct fake_sp {
	/* behaviour */
	enum sp_return by_name_rc; /* from call by_name_fail_from on */
	int by_name_fail_from;	   /* 1-based; 0 = never */
	enum sp_return open_rc;
	int open_errno;
	enum sp_return baud_rc;
	int write_fail_at; /* 1-based write that fails with write_errno */
	int write_errno;
	int full_from;	   /* 1-based write from which none is accepted */
	size_t accept_max; /* bytes accepted per write; 0 = all */
	int outq_fail_at;  /* 1-based sp_output_waiting that fails */
	bool wedged;	   /* queued bytes are never sent */
	enum sp_return handle_rc;
	int fd;		    /* descriptor handed out */
	bool answers;	    /* the board answers 0x5B */
	uint8_t states;	    /* devantech board: relay bits */
	uint8_t stuck;	    /* devantech board: bits that stay on */
	uint8_t ics_answer; /* icstation board: answer to 0x50 */
	bool icstation;
	uint8_t rx[16]; /* what the board has sent */
	size_t nrx;
	/* observations */
	uint8_t q[256]; /* in the driver's output queue */
	size_t nq;
	uint8_t wire[256]; /* sent to the board, in order */
	size_t nwire;
	int n_by_name, n_open, n_close, n_free, n_write, n_outq, n_flush;
	int n_nbread;
	int baud, bits, stopbits;
	enum sp_parity parity;
	enum sp_flowcontrol flow;
	enum sp_mode mode;
	bool is_open;
};

static struct fake_sp fk;

enum sp_return __wrap_sp_get_port_by_name(const char *portname,
					  struct sp_port **port_ptr);
enum sp_return __wrap_sp_open(struct sp_port *port, enum sp_mode flags);
enum sp_return __wrap_sp_close(struct sp_port *port);
void __wrap_sp_free_port(struct sp_port *port);
enum sp_return __wrap_sp_set_baudrate(struct sp_port *port, int baudrate);
enum sp_return __wrap_sp_set_bits(struct sp_port *port, int bits);
enum sp_return __wrap_sp_set_parity(struct sp_port *port,
				    enum sp_parity parity);
enum sp_return __wrap_sp_set_stopbits(struct sp_port *port, int stopbits);
enum sp_return __wrap_sp_set_flowcontrol(struct sp_port *port,
					 enum sp_flowcontrol flow);
enum sp_return __wrap_sp_blocking_write(struct sp_port *port, const void *buf,
					size_t count, unsigned int timeout_ms);
enum sp_return __wrap_sp_nonblocking_write(struct sp_port *port,
					   const void *buf, size_t count);
enum sp_return __wrap_sp_output_waiting(struct sp_port *port);
enum sp_return __wrap_sp_flush(struct sp_port *port, enum sp_buffer buffers);
enum sp_return __wrap_sp_drain(struct sp_port *port);
enum sp_return __wrap_sp_blocking_read(struct sp_port *port, void *buf,
				       size_t count, unsigned int timeout_ms);
enum sp_return __wrap_sp_nonblocking_read(struct sp_port *port, void *buf,
					  size_t count);
enum sp_return __wrap_sp_get_port_handle(const struct sp_port *port,
					 void *result_ptr);

enum sp_return __wrap_sp_get_port_by_name(const char *portname,
					  struct sp_port **port_ptr)
{
	assert_non_null(portname);
	fk.n_by_name++;
	if (fk.by_name_fail_from && fk.n_by_name >= fk.by_name_fail_from) {
		*port_ptr = NULL;
		return fk.by_name_rc;
	}
	*port_ptr = FAKE_PORT;
	return SP_OK;
}

enum sp_return __wrap_sp_open(struct sp_port *port, enum sp_mode flags)
{
	assert_ptr_equal(port, FAKE_PORT);
	assert_false(fk.is_open);
	fk.n_open++;
	fk.mode = flags;
	if (fk.open_rc != SP_OK) {
		errno = fk.open_errno;
		return fk.open_rc;
	}
	fk.is_open = true;
	return SP_OK;
}

/* A real close() with bytes queued waits up to closing_wait (30 s): the
 * module must have emptied or discarded the queue first. */
enum sp_return __wrap_sp_close(struct sp_port *port)
{
	assert_ptr_equal(port, FAKE_PORT);
	assert_true(fk.is_open);
	assert_int_equal(fk.nq, 0);
	fk.is_open = false;
	fk.n_close++;
	return SP_OK;
}

void __wrap_sp_free_port(struct sp_port *port)
{
	assert_ptr_equal(port, FAKE_PORT);
	assert_false(fk.is_open);
	fk.n_free++;
}

enum sp_return __wrap_sp_set_baudrate(struct sp_port *port, int baudrate)
{
	assert_true(port == FAKE_PORT && fk.is_open);
	fk.baud = baudrate;
	if (fk.baud_rc != SP_OK)
		errno = EINVAL;
	return fk.baud_rc;
}

enum sp_return __wrap_sp_set_bits(struct sp_port *port, int bits)
{
	assert_true(port == FAKE_PORT && fk.is_open);
	fk.bits = bits;
	return SP_OK;
}

enum sp_return __wrap_sp_set_parity(struct sp_port *port, enum sp_parity parity)
{
	assert_true(port == FAKE_PORT && fk.is_open);
	fk.parity = parity;
	return SP_OK;
}

enum sp_return __wrap_sp_set_stopbits(struct sp_port *port, int stopbits)
{
	assert_true(port == FAKE_PORT && fk.is_open);
	fk.stopbits = stopbits;
	return SP_OK;
}

enum sp_return __wrap_sp_set_flowcontrol(struct sp_port *port,
					 enum sp_flowcontrol flow)
{
	assert_true(port == FAKE_PORT && fk.is_open);
	fk.flow = flow;
	return SP_OK;
}

/* The calls with unbounded or whole-timeout waits must never be made. */
enum sp_return __wrap_sp_blocking_write(struct sp_port *port, const void *buf,
					size_t count, unsigned int timeout_ms)
{
	(void)port, (void)buf, (void)count, (void)timeout_ms;
	fail_msg("sp_blocking_write called");
	return SP_ERR_FAIL;
}

enum sp_return __wrap_sp_drain(struct sp_port *port)
{
	(void)port;
	fail_msg("sp_drain called");
	return SP_ERR_FAIL;
}

enum sp_return __wrap_sp_blocking_read(struct sp_port *port, void *buf,
				       size_t count, unsigned int timeout_ms)
{
	(void)port, (void)buf, (void)count, (void)timeout_ms;
	fail_msg("sp_blocking_read called");
	return SP_ERR_FAIL;
}

static void rx_add(uint8_t b)
{
	assert_true(fk.nrx < sizeof(fk.rx));
	fk.rx[fk.nrx++] = b;
}

/* One byte reaches the board. */
static void board_byte(uint8_t b)
{
	assert_true(fk.nwire < sizeof(fk.wire));
	fk.wire[fk.nwire++] = b;
	if (fk.icstation) {
		if (b == 0x50 && fk.ics_answer)
			rx_add(fk.ics_answer);
		return;
	}
	if (b >= 0x65 && b <= 0x6C)
		fk.states |= (uint8_t)(1u << (b - 0x65));
	else if (b >= 0x6F && b <= 0x76)
		fk.states &= (uint8_t) ~(1u << (b - 0x6F));
	else if (b == 0x5B && fk.answers)
		rx_add(fk.states | fk.stuck);
}

/* The adapter sends what it holds unless wedged. */
static void adapter_run(void)
{
	size_t i;

	if (fk.wedged)
		return;
	for (i = 0; i < fk.nq; i++)
		board_byte(fk.q[i]);
	fk.nq = 0;
}

/* libserialport 0.1.1: a full buffer is SP_ERR_FAIL with EAGAIN. */
enum sp_return __wrap_sp_nonblocking_write(struct sp_port *port,
					   const void *buf, size_t count)
{
	size_t n = count;

	assert_true(port == FAKE_PORT && fk.is_open);
	fk.n_write++;
	if (fk.n_write == fk.write_fail_at) {
		errno = fk.write_errno;
		return SP_ERR_FAIL;
	}
	if (fk.full_from && fk.n_write >= fk.full_from) {
		errno = EAGAIN;
		return SP_ERR_FAIL;
	}
	if (fk.accept_max && n > fk.accept_max)
		n = fk.accept_max;
	assert_true(fk.nq + n <= sizeof(fk.q));
	memcpy(fk.q + fk.nq, buf, n);
	fk.nq += n;
	adapter_run();
	return (enum sp_return)n;
}

enum sp_return __wrap_sp_output_waiting(struct sp_port *port)
{
	assert_true(port == FAKE_PORT && fk.is_open);
	fk.n_outq++;
	if (fk.n_outq == fk.outq_fail_at) {
		errno = EIO;
		return SP_ERR_FAIL;
	}
	adapter_run();
	return (enum sp_return)fk.nq;
}

enum sp_return __wrap_sp_flush(struct sp_port *port, enum sp_buffer buffers)
{
	assert_true(port == FAKE_PORT && fk.is_open);
	assert_int_equal(buffers, SP_BUF_OUTPUT);
	fk.n_flush++;
	fk.nq = 0;
	return SP_OK;
}

enum sp_return __wrap_sp_nonblocking_read(struct sp_port *port, void *buf,
					  size_t count)
{
	size_t n = count < fk.nrx ? count : fk.nrx;

	assert_true(port == FAKE_PORT && fk.is_open);
	fk.n_nbread++;
	memcpy(buf, fk.rx, n);
	memmove(fk.rx, fk.rx + n, fk.nrx - n);
	fk.nrx -= n;
	return (enum sp_return)n;
}

enum sp_return __wrap_sp_get_port_handle(const struct sp_port *port,
					 void *result_ptr)
{
	assert_true(port == FAKE_PORT && fk.is_open);
	if (fk.handle_rc != SP_OK)
		return fk.handle_rc;
	memcpy(result_ptr, &fk.fd, sizeof(int));
	return SP_OK;
}

/* ---- fixture ---- */

struct fix {
	int master, slave; /* the pty standing in for the port */
	char name[64];	   /* /dev/pts/N: the "port" path */
	char dir[64], state[128];
	struct re_relay_cfg cfg;
	char want[RE_RELAY_ERR_MAX];
};

static int setup(void **state)
{
	struct fix *f = calloc(1, sizeof(*f));
	struct termios t;

	assert_non_null(f);
	memset(&t, 0, sizeof(t));
	cfmakeraw(&t);
	assert_int_equal(openpty(&f->master, &f->slave, f->name, &t, NULL), 0);
	strcpy(f->dir, "/tmp/h4sp.XXXXXX");
	assert_non_null(mkdtemp(f->dir));
	snprintf(f->state, sizeof(f->state), "%s/ics.state", f->dir);
	memset(&fk, 0, sizeof(fk));
	fk.fd = f->slave;
	snprintf(f->cfg.port, sizeof(f->cfg.port), "%s", f->name);
	f->cfg.proto = RE_RELAY_DEVANTECH;
	f->cfg.channel = 1;
	f->cfg.backend = RE_RELAY_BACKEND_AUTO;
	f->cfg.clinical = true; /* auto -> libserialport */
	f->cfg.baud = 9600;
	f->cfg.write_timeout_ms = 30;
	f->cfg.off_deadline_ms = 20;
	f->cfg.readback_timeout_ms = 10000;
	snprintf(f->cfg.icstation_state, sizeof(f->cfg.icstation_state), "%s",
		 f->state);
	*state = f;
	return 0;
}

static int teardown(void **state)
{
	struct fix *f = *state;

	if (f->master >= 0)
		close(f->master);
	close(f->slave);
	unlink(f->state);
	rmdir(f->dir);
	free(f);
	return 0;
}

/* "relay '<port>': <text>" */
static const char *msg(struct fix *f, const char *text)
{
	snprintf(f->want, sizeof(f->want), "relay '%s': %s", f->name, text);
	return f->want;
}

static void wire_is(const uint8_t *want, size_t n)
{
	assert_int_equal(fk.nwire, n);
	assert_memory_equal(fk.wire, want, n);
	fk.nwire = 0;
}

static re_relay *open_ok(struct fix *f)
{
	char err[RE_RELAY_ERR_MAX];
	re_relay *r = NULL;

	if (re_relay_open(&r, &f->cfg, err, sizeof(err)) != GL_OK)
		fail_msg("re_relay_open: %s", err);
	assert_string_equal(err, "");
	return r;
}

static const uint8_t OFF1[] = {0x6F}, ON1[] = {0x65};

static int64_t mono_ns(void)
{
	return base_now_ns();
}

#define LATE_MS 15 /* a timeout may come this much after its deadline */

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

/* ---- tests ---- */

/* The good path: configuration, bytes, balanced open/close, nothing
 * discarded, no blocking call (the sp_blocking_* and sp_drain wraps fail). */
static void test_sp_good_path(void **state)
{
	struct fix *f = *state;
	re_relay *r = open_ok(f);

	assert_string_equal(re_relay_backend_name(r), "serialport");
	assert_int_equal(fk.mode, SP_MODE_READ_WRITE);
	assert_int_equal(fk.baud, 9600);
	assert_int_equal(fk.bits, 8);
	assert_int_equal(fk.parity, SP_PARITY_NONE);
	assert_int_equal(fk.stopbits, 1);
	assert_int_equal(fk.flow, SP_FLOWCONTROL_NONE);
	wire_is(OFF1, 1);
	assert_int_equal(fk.n_outq, 1);
	assert_int_equal(re_relay_state(r), RE_RELAY_OFF);
	assert_int_equal(re_relay_on(r), GL_OK);
	wire_is(ON1, 1);
	assert_int_equal(re_relay_state(r), RE_RELAY_ON);
	assert_int_equal(re_relay_check(r), GL_OK);
	assert_int_equal(fk.nwire + fk.nq, 0); /* the check writes nothing */
	assert_int_equal(re_relay_off(r), GL_OK);
	wire_is(OFF1, 1);
	assert_int_equal(re_relay_state(r), RE_RELAY_OFF);
	assert_int_equal(re_relay_close(r), GL_OK);
	wire_is(OFF1, 1);
	assert_int_equal(fk.n_write, 4);
	assert_int_equal(fk.n_outq, 5); /* one per message, one at close */
	assert_int_equal(fk.n_flush, 0);
	assert_int_equal(fk.n_by_name, 1);
	assert_int_equal(fk.n_open, 1);
	assert_int_equal(fk.n_close, 1);
	assert_int_equal(fk.n_free, 1);
}

/* libserialport does not know the port: nothing opened or written. */
static void test_sp_name_fails(void **state)
{
	struct fix *f = *state;
	char err[RE_RELAY_ERR_MAX];
	re_relay *r;

	fk.by_name_fail_from = 1;
	fk.by_name_rc = SP_ERR_ARG;
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)),
			 GL_ERR_RELAY);
	assert_null(r);
	assert_string_equal(err, msg(f, "cannot open: not a serial port "
					"known to libserialport"));
	assert_int_equal(fk.n_open + fk.n_free + (int)fk.nwire, 0);
}

/* sp_open fails (permissions): the port is freed, not closed. */
static void test_sp_open_fails(void **state)
{
	struct fix *f = *state;
	char err[RE_RELAY_ERR_MAX];
	re_relay *r;

	fk.open_rc = SP_ERR_FAIL;
	fk.open_errno = EACCES;
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)),
			 GL_ERR_RELAY);
	assert_string_equal(err, msg(f, "cannot open: Permission denied"));
	assert_int_equal(fk.n_free, 1);
	assert_int_equal(fk.n_close, 0);
	assert_int_equal(fk.nwire, 0);
}

/* The line settings are refused: closed and freed, nothing written. */
static void test_sp_configure_fails(void **state)
{
	struct fix *f = *state;
	char err[RE_RELAY_ERR_MAX];
	re_relay *r;

	fk.baud_rc = SP_ERR_FAIL;
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)),
			 GL_ERR_RELAY);
	assert_string_equal(err, msg(f, "cannot configure: Invalid argument"));
	assert_int_equal(fk.n_close, 1);
	assert_int_equal(fk.n_free, 1);
	assert_int_equal(fk.n_write, 0);
}

/* The first "off" cannot be written: the open fails (no reopen). */
static void test_sp_first_off_fails(void **state)
{
	struct fix *f = *state;
	char err[RE_RELAY_ERR_MAX];
	re_relay *r;

	fk.write_fail_at = 1;
	fk.write_errno = EIO;
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)),
			 GL_ERR_RELAY);
	assert_string_equal(err, msg(f, "write failed: Input/output error"));
	assert_int_equal(fk.n_open, 1);
	assert_int_equal(fk.n_close, 1);
	assert_int_equal(fk.n_free, 1);
	assert_int_equal(fk.nwire, 0);
}

/* "on" not accepted by the driver: timeout at write_timeout_ms, state
 * unknown, and the "on" is never written later (off writes only off). */
static void test_sp_on_not_accepted(void **state)
{
	struct fix *f = *state;
	re_relay *r = open_ok(f);
	int64_t t0;

	fk.nwire = 0;
	fk.full_from = 2;
	t0 = mono_ns();
	assert_int_equal(re_relay_on(r), GL_ERR_TIMEOUT);
	at_deadline("on, driver full", t0, 30);
	assert_string_equal(re_relay_errmsg(r),
			    msg(f, "on not confirmed: only 0 of 1 bytes "
				   "accepted by the driver within 30 ms"));
	assert_int_equal(re_relay_state(r), RE_RELAY_UNKNOWN);
	assert_int_equal(fk.n_flush, 1); /* the queue discarded */
	fk.full_from = 0;
	assert_int_equal(re_relay_off(r), GL_OK);
	wire_is(OFF1, 1);
	assert_int_equal(re_relay_close(r), GL_OK);
	wire_is(OFF1, 1);
}

/* "on" accepted but never sent: discarded at its deadline, the board
 * never sees it even when the adapter recovers. */
static void test_sp_on_discarded(void **state)
{
	struct fix *f = *state;
	re_relay *r = open_ok(f);
	int64_t t0;

	fk.nwire = 0;
	fk.wedged = true;
	t0 = mono_ns();
	assert_int_equal(re_relay_on(r), GL_ERR_TIMEOUT);
	at_deadline("on, queue wedged", t0, 30);
	assert_string_equal(re_relay_errmsg(r),
			    msg(f, "on not confirmed: 1 byte still queued "
				   "after 30 ms"));
	assert_int_equal(re_relay_state(r), RE_RELAY_UNKNOWN);
	assert_int_equal(fk.n_flush, 1);
	assert_int_equal(fk.nq, 0);
	fk.wedged = false;
	assert_int_equal(re_relay_close(r), GL_OK);
	wire_is(OFF1, 1);
}

/* The output queue cannot be read while confirming "on". */
static void test_sp_outq_fails(void **state)
{
	struct fix *f = *state;
	re_relay *r = open_ok(f);

	fk.outq_fail_at = 2;
	assert_int_equal(re_relay_on(r), GL_ERR_RELAY);
	assert_string_equal(
	    re_relay_errmsg(r),
	    msg(f, "output queue unreadable: Input/output error"));
	assert_int_equal(re_relay_state(r), RE_RELAY_UNKNOWN);
	assert_int_equal(fk.n_flush, 1);
	re_relay_close(r);
}

/* "off" fails once: reopened, written again, confirmed. */
static void test_sp_off_recovers(void **state)
{
	struct fix *f = *state;
	re_relay *r = open_ok(f);

	assert_int_equal(re_relay_on(r), GL_OK);
	fk.nwire = 0;
	fk.write_fail_at = 3;
	fk.write_errno = EIO;
	assert_int_equal(re_relay_off(r), GL_OK);
	assert_int_equal(re_relay_state(r), RE_RELAY_OFF);
	wire_is(OFF1, 1);
	assert_int_equal(fk.n_write, 4);
	assert_int_equal(fk.n_by_name, 2);
	assert_int_equal(fk.n_open, 2);
	assert_int_equal(fk.n_close, 1);
	assert_int_equal(fk.n_free, 1);
	assert_int_equal(re_relay_close(r), GL_OK);
	assert_int_equal(fk.n_close, 2);
	assert_int_equal(fk.n_free, 2);
}

/* "off" fails and the reopen fails: error with both reasons; later calls
 * keep trying and succeed once the port is back. */
static void test_sp_off_fails(void **state)
{
	struct fix *f = *state;
	re_relay *r = open_ok(f);

	assert_int_equal(re_relay_on(r), GL_OK);
	fk.write_fail_at = 3;
	fk.write_errno = EIO;
	fk.by_name_fail_from = 2;
	fk.by_name_rc = SP_ERR_ARG;
	assert_int_equal(re_relay_off(r), GL_ERR_RELAY);
	assert_string_equal(re_relay_errmsg(r),
			    msg(f, "write failed: Input/output error; "
				   "reopen: cannot open: not a serial port "
				   "known to libserialport"));
	assert_int_equal(re_relay_state(r), RE_RELAY_UNKNOWN);
	assert_int_equal(re_relay_check(r), GL_ERR_RELAY);
	assert_string_equal(re_relay_errmsg(r), msg(f, "port not open"));
	assert_int_equal(re_relay_on(r), GL_ERR_RELAY);
	assert_int_equal(re_relay_off(r), GL_ERR_RELAY);
	assert_string_equal(re_relay_errmsg(r),
			    msg(f, "write failed: port not open; reopen: "
				   "cannot open: not a serial port known to "
				   "libserialport"));
	fk.by_name_fail_from = 0; /* the relay is back */
	fk.nwire = 0;
	assert_int_equal(re_relay_off(r), GL_OK);
	wire_is(OFF1, 1);
	assert_int_equal(re_relay_state(r), RE_RELAY_OFF);
	assert_int_equal(re_relay_close(r), GL_OK);
	assert_int_equal(fk.n_open, fk.n_close);
	assert_int_equal(fk.n_free, 2);
}

/* A wedged adapter (its queue never empties): off returns the timeout at
 * its deadline, the byte stays queued (no reopen, no discard); close
 * discards the queue so that close() cannot wait. */
static void test_sp_off_wedged_queue(void **state)
{
	struct fix *f = *state;
	re_relay *r = open_ok(f);
	int64_t t0;

	assert_int_equal(re_relay_on(r), GL_OK);
	fk.nwire = 0;
	fk.wedged = true;
	t0 = mono_ns();
	assert_int_equal(re_relay_off(r), GL_ERR_TIMEOUT);
	at_deadline("off, queue wedged", t0, 20);
	assert_string_equal(re_relay_errmsg(r),
			    msg(f, "off not confirmed: 1 byte still queued "
				   "after 20 ms"));
	assert_int_equal(re_relay_state(r), RE_RELAY_UNKNOWN);
	assert_int_equal(fk.nq, 1);
	assert_int_equal(fk.n_flush, 0); /* the "off" stays queued */
	assert_int_equal(fk.n_open, 1);	 /* no reopen for a full queue */
	assert_int_equal(re_relay_check(r), GL_OK); /* no read-back here */
	t0 = mono_ns();
	assert_int_equal(re_relay_close(r), GL_ERR_TIMEOUT);
	at_deadline("close, queue wedged", t0, 20);
	assert_int_equal(fk.n_flush, 1);
	assert_int_equal(fk.n_close, 1);
	assert_int_equal(fk.nwire, 0);
}

/* The driver accepts nothing: off times out at its deadline; the next off,
 * once the driver takes bytes again, writes exactly one message. */
static void test_sp_off_not_accepted(void **state)
{
	struct fix *f = *state;
	re_relay *r = open_ok(f);
	int64_t t0;

	assert_int_equal(re_relay_on(r), GL_OK);
	fk.nwire = 0;
	fk.full_from = fk.n_write + 1;
	t0 = mono_ns();
	assert_int_equal(re_relay_off(r), GL_ERR_TIMEOUT);
	at_deadline("off, driver full", t0, 20);
	assert_string_equal(re_relay_errmsg(r),
			    msg(f, "off not confirmed: only 0 of 1 bytes "
				   "accepted by the driver within 20 ms"));
	assert_int_equal(re_relay_state(r), RE_RELAY_UNKNOWN);
	assert_int_equal(fk.n_open, 1);
	fk.full_from = 0;
	assert_int_equal(re_relay_off(r), GL_OK);
	wire_is(OFF1, 1);
	assert_int_equal(re_relay_close(r), GL_OK);
}

/* Split use: start returns at once, finish waits; a half-accepted LCUS
 * "off" is completed, never restarted or interleaved; misuse refused. */
static void test_sp_off_split(void **state)
{
	static const uint8_t off4[] = {0xA0, 0x01, 0x00, 0xA1};
	struct fix *f = *state;
	re_relay *r;
	int64_t t0;

	f->cfg.proto = RE_RELAY_LCUS;
	r = open_ok(f);
	wire_is(off4, 4);
	assert_int_equal(re_relay_off_finish(r, 20), GL_ERR_ARG);
	assert_int_equal(re_relay_on_finish(r, 20), GL_ERR_ARG);
	fk.accept_max = 2;
	fk.full_from = fk.n_write + 2; /* 2 bytes, then the buffer is full */
	t0 = mono_ns();
	assert_int_equal(re_relay_off_start(r), GL_OK);
	assert_true(mono_ns() - t0 < 5000000); /* did not wait */
	assert_int_equal(fk.nwire, 2); /* A0 01 sent, 00 A1 not accepted */
	assert_int_equal(re_relay_off_finish(r, -1), GL_ERR_ARG);
	assert_int_equal(re_relay_off_finish(r, 20), GL_ERR_TIMEOUT);
	at_deadline("off, half accepted", t0, 20);
	assert_string_equal(re_relay_errmsg(r),
			    msg(f, "off not confirmed: only 2 of 4 bytes "
				   "accepted by the driver within 20 ms"));
	assert_int_equal(re_relay_on(r), GL_ERR_RELAY);
	assert_string_equal(re_relay_errmsg(r),
			    msg(f, "on refused: the last message is not "
				   "written yet"));
	fk.full_from = 0;
	assert_int_equal(re_relay_off_start(r), GL_OK);
	assert_int_equal(re_relay_off_finish(r, 20), GL_OK);
	wire_is(off4, 4);
	assert_int_equal(re_relay_state(r), RE_RELAY_OFF);
	assert_int_equal(re_relay_close_start(r), GL_OK);
	assert_int_equal(re_relay_close_finish(r, 20), GL_OK);
	wire_is(off4, 4);
}

/* Devantech read-back in finish: a healthy board confirms at once; a
 * silent one is a timeout at the deadline, never earlier. */
static void test_sp_off_readback(void **state)
{
	static const uint8_t off_q[] = {0x6F, 0x5B}, on_q[] = {0x65, 0x5B};
	struct fix *f = *state;
	re_relay *r;
	int64_t t0;

	f->cfg.readback = true;
	fk.answers = true;
	r = open_ok(f);
	wire_is(off_q, 2);
	assert_int_equal(re_relay_on(r), GL_OK);
	wire_is(on_q, 2);
	t0 = mono_ns();
	assert_int_equal(re_relay_off(r), GL_OK);
	print_message("off with read-back confirmed in %.3f ms\n",
		      (double)(mono_ns() - t0) / 1e6);
	assert_true(mono_ns() - t0 < 5000000);
	wire_is(off_q, 2);
	assert_int_equal(re_relay_state(r), RE_RELAY_OFF);
	assert_int_equal(re_relay_on(r), GL_OK);
	wire_is(on_q, 2);
	fk.answers = false; /* the board stops answering */
	t0 = mono_ns();
	assert_int_equal(re_relay_off(r), GL_ERR_TIMEOUT);
	at_deadline("off, board silent", t0, 20);
	assert_string_equal(re_relay_errmsg(r),
			    msg(f, "off not confirmed: no answer to the state "
				   "query (0x5B) within 20 ms"));
	assert_int_equal(re_relay_state(r), RE_RELAY_UNKNOWN);
	wire_is(off_q, 2);
	fk.answers = true;
	assert_int_equal(re_relay_close(r), GL_OK);
	wire_is(off_q, 2);
}

/* Read-back after off shows the relay still on (a welded contact, a board
 * ignoring the byte): an error at once, not a timeout; state unknown. */
static void test_sp_off_readback_wrong(void **state)
{
	static const uint8_t off_q[] = {0x6F, 0x5B};
	struct fix *f = *state;
	re_relay *r;

	f->cfg.readback = true;
	fk.answers = true;
	r = open_ok(f);
	assert_int_equal(re_relay_on(r), GL_OK);
	fk.stuck = 0x01;
	fk.nwire = 0;
	assert_int_equal(re_relay_off(r), GL_ERR_RELAY);
	assert_string_equal(re_relay_errmsg(r),
			    msg(f, "off not confirmed: read-back shows "
				   "channel 1 on"));
	assert_int_equal(re_relay_state(r), RE_RELAY_UNKNOWN);
	wire_is(off_q, 2);
	assert_int_equal(fk.n_open, 1); /* no reopen for a board's answer */
	fk.stuck = 0;
	assert_int_equal(re_relay_close(r), GL_OK);
}

/* Devantech read-back through non-blocking calls only: the check's query
 * is answered in a later check; an answer still due when "off" starts is
 * skipped by the off's own read-back. */
static void test_sp_readback(void **state)
{
	static const uint8_t q1[] = {0x5B};
	static const uint8_t off_q[] = {0x6F, 0x5B}, on_q[] = {0x65, 0x5B};
	static const uint8_t due[] = {0x5B, 0x6F, 0x5B};
	struct fix *f = *state;
	re_relay *r;

	f->cfg.readback = true;
	fk.answers = true;
	r = open_ok(f);
	assert_int_equal(re_relay_on(r), GL_OK);
	fk.nwire = 0;
	fk.answers = false; /* the checks' answers are fed by hand */
	assert_int_equal(re_relay_check(r), GL_OK); /* sends the query */
	wire_is(q1, 1);
	assert_int_equal(re_relay_check(r), GL_OK); /* nothing yet: ok */
	rx_add(0x01);				    /* relay 1 on */
	assert_int_equal(re_relay_check(r), GL_OK);
	assert_int_equal(re_relay_check(r), GL_OK); /* next query */
	rx_add(0x01); /* its answer arrives as "off" starts */
	fk.answers = true;
	assert_int_equal(re_relay_off(r), GL_OK);
	wire_is(due, 3);
	assert_int_equal(fk.nrx, 0); /* both answers taken, in order */
	assert_int_equal(re_relay_check(r), GL_OK); /* query: 0x00 comes */
	assert_int_equal(re_relay_check(r), GL_OK); /* off, as written */
	wire_is(q1, 1);
	assert_int_equal(re_relay_on(r), GL_OK);
	wire_is(on_q, 2);
	fk.answers = false;
	assert_int_equal(re_relay_check(r), GL_OK);
	rx_add(0xFE); /* relay 1 dropped */
	assert_int_equal(re_relay_check(r), GL_ERR_RELAY);
	assert_string_equal(re_relay_errmsg(r),
			    msg(f, "read-back shows channel 1 off, expected "
				   "on"));
	fk.answers = true;
	fk.nwire = 0;
	assert_int_equal(re_relay_off(r), GL_OK);
	wire_is(off_q, 2);
	re_relay_close(r);
}

/* The checks' state query goes out at most every query_ms (a
 * fixed rate, not every cycle), answered or not; and at least twice within
 * readback_timeout_ms. */
static void test_sp_readback_rate(void **state)
{
	static const uint8_t q1[] = {0x5B};
	struct fix *f = *state;
	int64_t t0, dt_ms = -1;
	re_relay *r;

	f->cfg.readback = true;
	f->cfg.query_ms = 60;
	fk.answers = true;
	r = open_ok(f);
	assert_int_equal(re_relay_on(r), GL_OK);
	fk.nwire = 0;
	fk.answers = false;
	t0 = mono_ns();
	assert_int_equal(re_relay_check(r), GL_OK); /* sends the query */
	wire_is(q1, 1);
	rx_add(0x01);
	rx_add(0x00); /* a byte nobody awaits, in the same read: dropped */
	assert_int_equal(re_relay_check(r), GL_OK); /* reads its answer */
	assert_int_equal(fk.nrx, 0);
	while (mono_ns() - t0 < 2000 * BASE_NS_PER_MS) {
		assert_int_equal(re_relay_check(r), GL_OK);
		if (fk.nwire) {
			dt_ms = (mono_ns() - t0) / BASE_NS_PER_MS;
			break;
		}
	}
	print_message("second query after %lld ms (query_ms 60)\n",
		      (long long)dt_ms);
	assert_true(dt_ms >= 60 && dt_ms < 60 + LATE_MS);
	wire_is(q1, 1);
	re_relay_close(r);
	/* a short readback_timeout_ms: two queries fit in it */
	f->cfg.readback_timeout_ms = 40;
	fk.answers = true;
	r = open_ok(f);
	fk.nwire = 0;
	fk.answers = false;
	t0 = mono_ns();
	assert_int_equal(re_relay_check(r), GL_OK);
	wire_is(q1, 1);
	rx_add(0x00);
	dt_ms = -1;
	while (mono_ns() - t0 < 2000 * BASE_NS_PER_MS) {
		assert_int_equal(re_relay_check(r), GL_OK);
		if (fk.nwire) {
			dt_ms = (mono_ns() - t0) / BASE_NS_PER_MS;
			break;
		}
	}
	assert_true(dt_ms >= 20 && dt_ms < 20 + LATE_MS);
	re_relay_close(r);
}

/* The link checks: descriptor unavailable; hang-up on the line. */
static void test_sp_check_fails(void **state)
{
	struct fix *f = *state;
	re_relay *r = open_ok(f);

	assert_int_equal(re_relay_check(r), GL_OK);
	fk.handle_rc = SP_ERR_ARG;
	assert_int_equal(re_relay_check(r), GL_ERR_RELAY);
	assert_string_equal(re_relay_errmsg(r),
			    msg(f, "descriptor lost: Bad file descriptor"));
	fk.handle_rc = SP_OK;
	assert_int_equal(re_relay_check(r), GL_OK);
	close(f->master); /* the far side goes away */
	f->master = -1;
	assert_int_equal(re_relay_check(r), GL_ERR_RELAY);
	assert_string_equal(re_relay_errmsg(r), msg(f, "link lost (hang-up)"));
	assert_int_equal(fk.nwire, 1); /* only the open's "off" */
	re_relay_close(r);
}

/* ICStation: handshake once per board power-up, recorded in the state
 * file; a board that does not answer is switched all off and refused. */
static void test_sp_icstation(void **state)
{
	static const uint8_t first[] = {0x50, 0x51, 0xFF};
	static const uint8_t refused[] = {0x50, 0xFF};
	static const uint8_t off[] = {0xFF};
	struct fix *f = *state;
	char err[RE_RELAY_ERR_MAX];
	re_relay *r;

	f->cfg.proto = RE_RELAY_ICSTATION;
	fk.icstation = true;
	rx_add(0x99);	      /* line noise: dropped */
	fk.ics_answer = 0xAD; /* ICSE013A */
	r = open_ok(f);
	wire_is(first, 3);
	assert_int_equal(fk.nrx, 0);
	assert_int_equal(re_relay_close(r), GL_OK);
	wire_is(off, 1);
	r = open_ok(f); /* same power-up */
	wire_is(off, 1);
	assert_int_equal(re_relay_close(r), GL_OK);
	wire_is(off, 1);
	unlink(f->state); /* record lost: ask again */
	fk.ics_answer = 0;
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)),
			 GL_ERR_RELAY);
	assert_string_equal(err,
			    msg(f, "no answer to the icstation "
				   "handshake within 500 ms (board already "
				   "initialised?): unplug and re-plug the "
				   "relay"));
	wire_is(refused, 2);
	fk.ics_answer = 0x42; /* not a model byte */
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)),
			 GL_ERR_RELAY);
	assert_string_equal(err, msg(f, "unexpected answer 0x42 to the "
					"icstation handshake"));
	wire_is(refused, 2);
	assert_int_equal(fk.n_open, fk.n_close);
}

/* Clinical mode: the tty back-end is refused before any call. */
static void test_sp_clinical_tty_refused(void **state)
{
	struct fix *f = *state;
	char err[RE_RELAY_ERR_MAX];
	re_relay *r;

	f->cfg.backend = RE_RELAY_BACKEND_TTY;
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)),
			 GL_ERR_ARG);
	assert_string_equal(err, msg(f, "the tty back-end is not allowed in "
					"clinical mode"));
	assert_int_equal(fk.n_by_name, 0);
	f->cfg.backend = RE_RELAY_BACKEND_AUTO;
	f->cfg.channel = 9;
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)),
			 GL_ERR_ARG);
	assert_string_equal(err, msg(f, "invalid channel 9 or empty message"));
	assert_int_equal(fk.n_by_name, 0);
}

#define T(fn) cmocka_unit_test_setup_teardown(fn, setup, teardown)

int main(void)
{
	static const struct CMUnitTest tests[] = {
	    T(test_sp_good_path),	   T(test_sp_name_fails),
	    T(test_sp_open_fails),	   T(test_sp_configure_fails),
	    T(test_sp_first_off_fails),	   T(test_sp_on_not_accepted),
	    T(test_sp_on_discarded),	   T(test_sp_outq_fails),
	    T(test_sp_off_recovers),	   T(test_sp_off_fails),
	    T(test_sp_off_wedged_queue),   T(test_sp_off_not_accepted),
	    T(test_sp_off_split),	   T(test_sp_off_readback),
	    T(test_sp_off_readback_wrong), T(test_sp_check_fails),
	    T(test_sp_readback),	   T(test_sp_readback_rate),
	    T(test_sp_icstation),	   T(test_sp_clinical_tty_refused),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
