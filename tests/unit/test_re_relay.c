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
#include <unistd.h>

#include <cmocka.h>

#include "gl_err.h"
#include "re_relay.h"

/* ---- the fake libserialport ---- */

static char fake_port_storage;
#define FAKE_PORT ((struct sp_port *)&fake_port_storage)

struct fake_sp {
	/* behaviour */
	enum sp_return by_name_rc; /* from call by_name_fail_from on */
	int by_name_fail_from;	   /* 1-based; 0 = never */
	enum sp_return open_rc;
	int open_errno;
	enum sp_return baud_rc;
	int write_fail_at; /* 1-based blocking write that fails */
	int write_errno;
	int write_short_at; /* 1-based blocking write taking 0 */
	int drain_fail_at;  /* 1-based drain that fails */
	enum sp_return handle_rc;
	int fd;		/* descriptor handed out */
	uint8_t rx[16]; /* what the board has sent ... */
	size_t nrx;
	uint8_t brx[16]; /* ... and what it sends in answer to
			  * a byte (blocking reads) */
	size_t nbrx;
	/* observations */
	uint8_t wire[256]; /* bytes accepted, in order */
	size_t nwire;
	int n_by_name, n_open, n_close, n_free, n_write, n_nbwrite, n_drain;
	int n_bread, n_nbread;
	int baud, bits, stopbits;
	enum sp_parity parity;
	enum sp_flowcontrol flow;
	enum sp_mode mode;
	unsigned int timeout_ms;
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

enum sp_return __wrap_sp_close(struct sp_port *port)
{
	assert_ptr_equal(port, FAKE_PORT);
	assert_true(fk.is_open);
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

static void wire_add(const void *buf, size_t n)
{
	assert_true(fk.nwire + n <= sizeof(fk.wire));
	memcpy(fk.wire + fk.nwire, buf, n);
	fk.nwire += n;
}

enum sp_return __wrap_sp_blocking_write(struct sp_port *port, const void *buf,
					size_t count, unsigned int timeout_ms)
{
	assert_true(port == FAKE_PORT && fk.is_open);
	fk.n_write++;
	fk.timeout_ms = timeout_ms;
	if (fk.n_write == fk.write_fail_at) {
		errno = fk.write_errno;
		return SP_ERR_FAIL;
	}
	if (fk.n_write == fk.write_short_at)
		return (enum sp_return)0;
	wire_add(buf, count);
	return (enum sp_return)count;
}

enum sp_return __wrap_sp_nonblocking_write(struct sp_port *port,
					   const void *buf, size_t count)
{
	assert_true(port == FAKE_PORT && fk.is_open);
	fk.n_nbwrite++;
	wire_add(buf, count);
	return (enum sp_return)count;
}

enum sp_return __wrap_sp_drain(struct sp_port *port)
{
	assert_true(port == FAKE_PORT && fk.is_open);
	fk.n_drain++;
	if (fk.n_drain == fk.drain_fail_at) {
		errno = EIO;
		return SP_ERR_FAIL;
	}
	return SP_OK;
}

static enum sp_return take(uint8_t *q, size_t *nq, void *buf, size_t count)
{
	size_t n = count < *nq ? count : *nq;

	memcpy(buf, q, n);
	memmove(q, q + n, *nq - n);
	*nq -= n;
	return (enum sp_return)n;
}

enum sp_return __wrap_sp_blocking_read(struct sp_port *port, void *buf,
				       size_t count, unsigned int timeout_ms)
{
	assert_true(port == FAKE_PORT && fk.is_open);
	assert_true(timeout_ms > 0);
	fk.n_bread++;
	return take(fk.brx, &fk.nbrx, buf, count);
}

enum sp_return __wrap_sp_nonblocking_read(struct sp_port *port, void *buf,
					  size_t count)
{
	assert_true(port == FAKE_PORT && fk.is_open);
	fk.n_nbread++;
	return take(fk.rx, &fk.nrx, buf, count);
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
	f->cfg.write_timeout_ms = 100;
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

/* ---- tests ---- */

/* The good path: configuration, bytes, drains, balanced open/close. */
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
	assert_int_equal(fk.timeout_ms, 100);
	wire_is(OFF1, 1);
	assert_int_equal(fk.n_drain, 1);
	assert_int_equal(re_relay_on(r), GL_OK);
	wire_is(ON1, 1);
	assert_int_equal(re_relay_check(r), GL_OK);
	assert_int_equal(fk.nwire, 0); /* the check writes nothing */
	assert_int_equal(fk.n_nbwrite, 0);
	assert_int_equal(re_relay_off(r), GL_OK);
	wire_is(OFF1, 1);
	assert_int_equal(re_relay_close(r), GL_OK);
	wire_is(OFF1, 1);
	assert_int_equal(fk.n_drain, 4);
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

/* The first "off" cannot be written: the open fails. */
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
	assert_int_equal(fk.n_close, 1);
	assert_int_equal(fk.n_free, 1);
	assert_int_equal(fk.n_drain, 0);
}

/* "on" taken short (timeout): error, state unknown, no drain. */
static void test_sp_on_short_write(void **state)
{
	struct fix *f = *state;
	re_relay *r = open_ok(f);

	fk.nwire = 0;
	fk.write_short_at = 2;
	assert_int_equal(re_relay_on(r), GL_ERR_RELAY);
	assert_string_equal(re_relay_errmsg(r),
			    msg(f, "write failed: only 0 of 1 bytes written "
				   "within 100 ms"));
	assert_int_equal(re_relay_state(r), RE_RELAY_UNKNOWN);
	assert_int_equal(fk.n_drain, 1); /* only the open's */
	assert_int_equal(fk.nwire, 0);
	re_relay_close(r);
}

/* The drain of "on" fails. */
static void test_sp_drain_fails(void **state)
{
	struct fix *f = *state;
	re_relay *r = open_ok(f);

	fk.drain_fail_at = 2;
	assert_int_equal(re_relay_on(r), GL_ERR_RELAY);
	assert_string_equal(re_relay_errmsg(r),
			    msg(f, "drain failed: Input/output error"));
	assert_int_equal(re_relay_state(r), RE_RELAY_UNKNOWN);
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

/* Devantech read-back through non-blocking calls only. */
static void test_sp_readback(void **state)
{
	static const uint8_t query[] = {0x5B};
	struct fix *f = *state;
	re_relay *r;

	f->cfg.readback = true;
	r = open_ok(f);
	assert_int_equal(re_relay_on(r), GL_OK);
	fk.nwire = 0;
	assert_int_equal(re_relay_check(r), GL_OK); /* sends the query */
	wire_is(query, 1);
	assert_int_equal(fk.n_nbwrite, 1);
	assert_int_equal(re_relay_check(r), GL_OK); /* nothing yet: ok */
	assert_int_equal(fk.nwire, 0);
	fk.rx[fk.nrx++] = 0x01; /* relay 1 on */
	assert_int_equal(re_relay_check(r), GL_OK);
	assert_int_equal(re_relay_check(r), GL_OK); /* next query */
	wire_is(query, 1);
	/* An answer that predates an "off" is not judged. */
	assert_int_equal(re_relay_off(r), GL_OK);
	fk.nwire = 0;
	fk.rx[fk.nrx++] = 0x01;
	assert_int_equal(re_relay_check(r), GL_OK);
	assert_int_equal(re_relay_check(r), GL_OK);
	wire_is(query, 1);
	fk.rx[fk.nrx++] = 0x00; /* off, as written */
	assert_int_equal(re_relay_check(r), GL_OK);
	assert_int_equal(re_relay_on(r), GL_OK);
	assert_int_equal(re_relay_check(r), GL_OK);
	fk.rx[fk.nrx++] = 0xFE; /* relay 1 dropped */
	assert_int_equal(re_relay_check(r), GL_ERR_RELAY);
	assert_string_equal(re_relay_errmsg(r),
			    msg(f, "read-back shows channel 1 off, expected "
				   "on"));
	assert_int_equal(fk.n_bread, 0); /* never a blocking read */
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
	fk.rx[fk.nrx++] = 0x99;	  /* line noise: dropped */
	fk.brx[fk.nbrx++] = 0xAD; /* ICSE013A */
	r = open_ok(f);
	wire_is(first, 3);
	assert_int_equal(fk.n_bread, 1);
	assert_int_equal(re_relay_close(r), GL_OK);
	wire_is(off, 1);
	r = open_ok(f); /* same power-up */
	wire_is(off, 1);
	assert_int_equal(fk.n_bread, 1);
	assert_int_equal(re_relay_close(r), GL_OK);
	fk.nwire = 0;
	unlink(f->state); /* record lost: ask again */
	assert_int_equal(re_relay_open(&r, &f->cfg, err, sizeof(err)),
			 GL_ERR_RELAY);
	assert_string_equal(err,
			    msg(f, "no answer to the icstation "
				   "handshake within 500 ms (board already "
				   "initialised?): unplug and re-plug the "
				   "relay"));
	wire_is(refused, 2);
	fk.brx[fk.nbrx++] = 0x42; /* not a model byte */
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
	    T(test_sp_good_path),
	    T(test_sp_name_fails),
	    T(test_sp_open_fails),
	    T(test_sp_configure_fails),
	    T(test_sp_first_off_fails),
	    T(test_sp_on_short_write),
	    T(test_sp_drain_fails),
	    T(test_sp_off_recovers),
	    T(test_sp_off_fails),
	    T(test_sp_check_fails),
	    T(test_sp_readback),
	    T(test_sp_icstation),
	    T(test_sp_clinical_tty_refused),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
