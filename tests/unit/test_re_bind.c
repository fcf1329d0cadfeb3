/*
 * test_re_bind.c - the E-stop relay bound by its USB serial number: the
 * serial number's rule, the choice among ports, the udev rule's exact text
 * and the clinical start-up's comparison (pc/config/re_bind), and
 * roboelf-tech bind-relay (tools/roboelf-tech/re_bindrelay) over a listing
 * given here, writing into a temporary directory. libserialport's listing
 * (re_bindrelay_list_sp) and the start-up's reading of the relay's serial
 * number (re_relay_usb_serial, pc/super/re_relay_sp.c) run over the
 * linker's --wrap of every sp_* call they make (test_re_bind.ldflags): no
 * serial device is listed, read or opened.
 *
 * Covered: allowed and refused serial numbers with their exact messages;
 * the choice with and without --serial (none, one, several, duplicates,
 * no serial number); the rule file's exact text; the comparison's three
 * refusals; bind-relay writing only the chosen board's rule, and leaving
 * an existing file untouched on every refusal; the listing keeping USB
 * ports only; the serial number read through a link to the port's node.
 */
#include <errno.h>
#include <libserialport.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "gl_err.h"
#include "re_bind.h"
#include "re_bindrelay.h"
#include "re_relay.h"

#define FIX " (docs/technician.md, section 10)"

/* Two boards as libserialport would describe them. */
static const struct re_bind_port relay = {"/dev/ttyTEST0", "FT232R USB UART",
					  "A10KXYZ9", 0x0403, 0x6001};
static const struct re_bind_port cable = {"/dev/ttyTEST1", "USB2.0-Serial", "",
					  0x1a86, 0x7523};
static const struct re_bind_port other = {"/dev/ttyTEST2", "FT232R USB UART",
					  "B22QRST1", 0x0403, 0x6001};

#define RULE_LINE(serial)                                                      \
	"SUBSYSTEM==\"tty\", ATTRS{idVendor}==\"0403\", "                      \
	"ATTRS{idProduct}==\"6001\", ATTRS{serial}==\"" serial "\", "          \
	"SYMLINK+=\"roboelf-relay\", GROUP=\"roboelf\", MODE=\"0660\"\n"

#define RULE_FILE(serial)                                                      \
	"# 60-roboelf-relay.rules - the E-stop relay of this robot, bound by " \
	"its USB\n"                                                            \
	"# serial number (written by 'roboelf-tech bind-relay'; "              \
	"docs/technician.md,\n"                                                \
	"# section 10): the name /dev/roboelf-relay for this one board only, " \
	"and\n"                                                                \
	"# read and write access for the group roboelf. It masks the "         \
	"package's rule\n"                                                     \
	"# of the same name in /lib/udev/rules.d, which names no board. To "   \
	"bind\n"                                                               \
	"# another board, run 'roboelf-tech bind-relay' again.\n" RULE_LINE(   \
	    serial)

static const char rule_text[] = RULE_FILE("A10KXYZ9");

/* ---- the serial number's rule ---- */

/* Letters, digits, '.', '_', '-', ':' up to 64 characters; nothing else. */
static void test_serial_check(void **state)
{
	char err[RE_BIND_ERR_MAX], s[80];

	(void)state;
	assert_int_equal(re_bind_serial_check("A10KXYZ9", err, sizeof(err)),
			 GL_OK);
	assert_int_equal(re_bind_serial_check("ab-09_.:Z", NULL, 0), GL_OK);
	memset(s, 'A', 64);
	s[64] = '\0';
	assert_int_equal(re_bind_serial_check(s, err, sizeof(err)), GL_OK);
	s[64] = 'B';
	s[65] = '\0';
	assert_int_equal(re_bind_serial_check(s, err, sizeof(err)),
			 GL_ERR_FORMAT);
	assert_string_equal(err, "serial number '"
				 "AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA"
				 "AAAAAAAAAAAAAAAAAAAAAAAA...' is longer "
				 "than 64 characters");
	assert_int_equal(re_bind_serial_check("", err, sizeof(err)),
			 GL_ERR_FORMAT);
	assert_string_equal(err, "the serial number is empty");
	assert_int_equal(re_bind_serial_check(NULL, err, sizeof(err)),
			 GL_ERR_FORMAT);
	assert_int_equal(re_bind_serial_check("A1\"B", err, sizeof(err)),
			 GL_ERR_FORMAT);
	assert_string_equal(err, "serial number 'A1\"B' has a character not "
				 "allowed in a udev rule ('\"' at position "
				 "3): only letters, digits, '.', '_', '-' and "
				 "':'");
	assert_int_equal(re_bind_serial_check("A1 B", err, sizeof(err)),
			 GL_ERR_FORMAT);
	assert_string_equal(err, "serial number 'A1 B' has a character not "
				 "allowed in a udev rule (' ' at position "
				 "3): only letters, digits, '.', '_', '-' and "
				 "':'");
	/* a pattern would match other boards too */
	assert_int_equal(re_bind_serial_check("A1*", NULL, 0), GL_ERR_FORMAT);
	assert_int_equal(re_bind_serial_check("A1?", NULL, 0), GL_ERR_FORMAT);
	assert_int_equal(re_bind_serial_check("A[1]", NULL, 0), GL_ERR_FORMAT);
	assert_int_equal(re_bind_serial_check("A|B", NULL, 0), GL_ERR_FORMAT);
	assert_int_equal(re_bind_serial_check("A\\B", NULL, 0), GL_ERR_FORMAT);
	assert_int_equal(re_bind_serial_check("A$B", NULL, 0), GL_ERR_FORMAT);
	assert_int_equal(re_bind_serial_check("A\nB", err, sizeof(err)),
			 GL_ERR_FORMAT);
	assert_string_equal(err, "serial number 'A?B' has a character not "
				 "allowed in a udev rule (byte 0x0a at "
				 "position 2): only letters, digits, '.', '_', "
				 "'-' and ':'");
	assert_int_equal(re_bind_serial_check("A\xc3\xa9", NULL, 0),
			 GL_ERR_FORMAT);
}

/* ---- the choice ---- */

/* Without --serial: the one port there is, with a serial number. */
static void test_choose_one(void **state)
{
	struct re_bind_port p[3] = {relay, cable, other};
	char err[RE_BIND_ERR_MAX];
	size_t k = 99;

	(void)state;
	assert_int_equal(re_bind_choose(p, 1, NULL, &k, err, sizeof(err)),
			 GL_OK);
	assert_int_equal(k, 0);
	assert_int_equal(re_bind_choose(p, 0, NULL, &k, err, sizeof(err)),
			 GL_ERR_NOENT);
	assert_string_equal(err, "no USB serial port found: plug in the relay "
				 "board and run again");
	assert_int_equal(re_bind_choose(p, 2, NULL, &k, err, sizeof(err)),
			 GL_ERR_ARG);
	assert_string_equal(err, "2 USB serial ports found: unplug every one "
				 "but the relay board and run again, or name "
				 "it with --serial SERIAL");
	assert_int_equal(re_bind_choose(&p[1], 1, NULL, &k, err, sizeof(err)),
			 GL_ERR_NOENT);
	assert_string_equal(err, "the one USB serial port, '/dev/ttyTEST1', has "
				 "no USB serial number: it cannot be bound; "
				 "use a relay board that has one" FIX);
	strcpy(p[0].serial, "A1*");
	assert_int_equal(re_bind_choose(p, 1, NULL, &k, err, sizeof(err)),
			 GL_ERR_FORMAT);
	assert_string_equal(err, "serial number 'A1*' has a character not "
				 "allowed in a udev rule ('*' at position "
				 "3): only letters, digits, '.', '_', '-' and "
				 "':'");
}

/* With --serial: the one port of that serial number, among any. */
static void test_choose_wanted(void **state)
{
	struct re_bind_port p[4] = {relay, cable, other, relay};
	char err[RE_BIND_ERR_MAX];
	size_t k = 99;

	(void)state;
	assert_int_equal(re_bind_choose(p, 3, "B22QRST1", &k, err, sizeof(err)),
			 GL_OK);
	assert_int_equal(k, 2);
	assert_int_equal(re_bind_choose(p, 3, "A10KXYZ9", &k, err, sizeof(err)),
			 GL_OK);
	assert_int_equal(k, 0);
	assert_int_equal(re_bind_choose(p, 3, "C3", &k, err, sizeof(err)),
			 GL_ERR_NOENT);
	assert_string_equal(err, "no USB serial port has the serial number "
				 "'C3' (3 found): plug in that relay board and "
				 "run again");
	assert_int_equal(re_bind_choose(p, 0, "C3", &k, err, sizeof(err)),
			 GL_ERR_NOENT);
	assert_string_equal(err, "no USB serial port found: plug in the relay "
				 "board and run again");
	/* two boards of one serial number: a rule cannot tell them apart */
	assert_int_equal(re_bind_choose(p, 4, "A10KXYZ9", &k, err, sizeof(err)),
			 GL_ERR_ARG);
	assert_string_equal(err, "2 USB serial ports have the serial number "
				 "'A10KXYZ9': a rule by serial number cannot "
				 "tell them apart; unplug every board but the "
				 "relay");
	assert_int_equal(re_bind_choose(p, 3, "A1\"", &k, err, sizeof(err)),
			 GL_ERR_FORMAT);
	assert_string_equal(err, "serial number 'A1\"' has a character not "
				 "allowed in a udev rule ('\"' at position "
				 "3): only letters, digits, '.', '_', '-' and "
				 "':'");
}

/* ---- the rule ---- */

/* The whole file, exactly; nothing but the ids and the serial number of
 * the device in it. */
static void test_rule_text(void **state)
{
	struct re_bind_port p = relay;
	char buf[RE_BIND_RULE_MAX], err[RE_BIND_ERR_MAX];

	(void)state;
	strcpy(p.desc, "evil\nSUBSYSTEM==\"tty\", SYMLINK+=\"roboelf-relay\"");
	assert_int_equal(re_bind_rule(&p, buf, sizeof(buf), err, sizeof(err)),
			 (int)strlen(rule_text));
	assert_string_equal(buf, rule_text);
	assert_int_equal(re_bind_rule(&p, buf, 100, err, sizeof(err)),
			 GL_ERR_OVERFLOW);
	assert_string_equal(err, "the rule does not fit 100 bytes");
	p.serial[0] = '\0';
	assert_int_equal(re_bind_rule(&p, buf, sizeof(buf), err, sizeof(err)),
			 GL_ERR_FORMAT);
	assert_string_equal(err, "the serial number is empty");
	p = relay;
	p.vid = 0x10000;
	assert_int_equal(re_bind_rule(&p, buf, sizeof(buf), err, sizeof(err)),
			 GL_ERR_RANGE);
	assert_string_equal(err, "USB id 10000:6001 is not two 16-bit numbers");
}

/* ---- the clinical start-up's comparison ---- */

static void test_verify(void **state)
{
	char err[RE_BIND_ERR_MAX];

	(void)state;
	assert_int_equal(re_bind_verify("/dev/roboelf-relay", "A10KXYZ9",
					"A10KXYZ9", err, sizeof(err)),
			 GL_OK);
	assert_int_equal(re_bind_verify("/dev/roboelf-relay", "B22QRST1",
					"A10KXYZ9", err, sizeof(err)),
			 GL_ERR_MISMATCH);
	assert_string_equal(
	    err, "the E-stop relay '/dev/roboelf-relay' is not the board bound "
		 "to this robot: its USB serial number is 'B22QRST1', "
		 "relay.serial is 'A10KXYZ9'; plug in the bound board, or bind "
		 "this one with 'roboelf-tech bind-relay' and set relay.serial "
		 "to its serial number" FIX);
	assert_int_equal(re_bind_verify("/dev/roboelf-relay", "", "A10KXYZ9",
					err, sizeof(err)),
			 GL_ERR_NOENT);
	assert_string_equal(
	    err, "the E-stop relay '/dev/roboelf-relay' has no USB serial "
		 "number (relay.serial is 'A10KXYZ9'): clinical mode needs the "
		 "board bound to this robot by its serial number; plug in the "
		 "board bound with 'roboelf-tech bind-relay'" FIX);
	assert_int_equal(re_bind_verify("/dev/roboelf-relay", "A10KXYZ9", "",
					err, sizeof(err)),
			 GL_ERR_CONFIG);
	assert_string_equal(
	    err, "the E-stop relay '/dev/roboelf-relay' is not bound to this "
		 "robot: relay.serial is not set; bind the board with "
		 "'roboelf-tech bind-relay' and set relay.serial to the serial "
		 "number it prints" FIX);
	/* a prefix is not the serial number; what the board says is shown
	 * safely */
	assert_int_equal(
	    re_bind_verify("/dev/x", "A10KXYZ", "A10KXYZ9", NULL, 0),
	    GL_ERR_MISMATCH);
	assert_int_equal(
	    re_bind_verify("/dev/x", "A\x1b[2J", "A10KXYZ9", err, sizeof(err)),
	    GL_ERR_MISMATCH);
	assert_non_null(strstr(err, "its USB serial number is 'A?[2J'"));
}

/* ---- roboelf-tech bind-relay ---- */

static struct re_bind_port listed[4];
static size_t n_listed;
static int list_rc;

static int fake_list(struct re_bind_port *ports, size_t cap, size_t *n,
		     char *err, size_t errlen)
{
	assert_true(cap >= n_listed);
	memcpy(ports, listed, n_listed * sizeof(listed[0]));
	*n = n_listed;
	if (list_rc)
		snprintf(err, errlen, "cannot list the serial ports: %s",
			 strerror(EIO));
	return list_rc;
}

struct run {
	char dir[64], rules[96];
	char *out, *err;
	size_t out_len, err_len;
};

static int setup(void **state)
{
	struct run *r = calloc(1, sizeof(*r));

	if (!r)
		return -1;
	snprintf(r->dir, sizeof(r->dir), "/tmp/test_re_bind.XXXXXX");
	if (!mkdtemp(r->dir)) {
		free(r);
		return -1;
	}
	snprintf(r->rules, sizeof(r->rules), "%s/60-roboelf-relay.rules",
		 r->dir);
	list_rc = GL_OK;
	n_listed = 0;
	*state = r;
	return 0;
}

static int teardown(void **state)
{
	struct run *r = *state;
	char tmp[128];

	snprintf(tmp, sizeof(tmp), "%s.tmp", r->rules);
	unlink(tmp);
	unlink(r->rules);
	rmdir(r->dir);
	free(r->out);
	free(r->err);
	free(r);
	return 0;
}

/* bind-relay with @serial (NULL: none) into the test's rules file. */
static int run(struct run *r, const char *serial)
{
	struct re_bindrelay_opts o = {serial, r->rules};
	FILE *out, *err;
	int rc;

	free(r->out);
	free(r->err);
	out = open_memstream(&r->out, &r->out_len);
	err = open_memstream(&r->err, &r->err_len);
	assert_non_null(out);
	assert_non_null(err);
	rc = re_bindrelay_run(&o, fake_list, out, err);
	fclose(out);
	fclose(err);
	return rc;
}

/* The whole of @path ("" when it does not exist). */
static const char *file_text(const char *path)
{
	static char buf[4096];
	FILE *f = fopen(path, "r");
	size_t n = 0;

	if (f) {
		n = fread(buf, 1, sizeof(buf) - 1, f);
		fclose(f);
	}
	buf[n] = '\0';
	return buf;
}

/* --serial among three ports: only that board's rule is written, and the
 * technician is told the next steps. */
static void test_run_serial(void **state)
{
	struct run *r = *state;
	char want[2048];
	struct stat st;

	umask(022);
	listed[0] = relay;
	listed[1] = cable;
	listed[2] = other;
	n_listed = 3;
	assert_int_equal(run(r, "B22QRST1"), 0);
	assert_string_equal(r->err, "");
	assert_string_equal(file_text(r->rules), RULE_FILE("B22QRST1"));
	assert_int_equal(stat(r->rules, &st), 0);
	assert_int_equal(st.st_mode & 0777, 0644);
	snprintf(
	    want, sizeof(want),
	    "bind-relay: 3 USB serial ports found:\n"
	    "  /dev/ttyTEST0  USB 0403:6001  serial number 'A10KXYZ9'  FT232R "
	    "USB UART\n"
	    "  /dev/ttyTEST1  USB 1a86:7523  serial number none  USB2.0-Serial\n"
	    "  /dev/ttyTEST2  USB 0403:6001  serial number 'B22QRST1'  FT232R "
	    "USB UART\n"
	    "bind-relay: the relay board: /dev/ttyTEST2, USB 0403:6001, serial "
	    "number 'B22QRST1'\n"
	    "bind-relay: wrote %s:\n" RULE_LINE(
		"B22QRST1") "bind-relay: next, as root: udevadm control "
			    "--reload && udevadm "
			    "trigger\n"
			    "bind-relay: then check: ls -l /dev/roboelf-relay "
			    "(a link to "
			    "ttyTEST2)\n"
			    "bind-relay: and set in the configuration (relay:) "
			    "serial: "
			    "B22QRST1\n",
	    r->rules);
	assert_string_equal(r->out, want);
}

/* The one board, no --serial: its rule, exactly the file re_bind_rule()
 * makes; an older rule is replaced whole. */
static void test_run_one(void **state)
{
	struct run *r = *state;
	FILE *f = fopen(r->rules, "w");

	assert_non_null(f);
	fputs("old rule\n", f);
	fclose(f);
	listed[0] = relay;
	n_listed = 1;
	assert_int_equal(run(r, NULL), 0);
	assert_string_equal(r->err, "");
	assert_string_equal(file_text(r->rules), rule_text);
}

/* Every refusal: exit 3 (2 for a file that cannot be written), the reason
 * on the error stream, and the rules file as it was. */
static void test_run_refused(void **state)
{
	struct run *r = *state;
	FILE *f = fopen(r->rules, "w");

	assert_non_null(f);
	fputs("old rule\n", f);
	fclose(f);
	listed[0] = relay;
	listed[1] = other;
	n_listed = 2;
	assert_int_equal(run(r, NULL), 3);
	assert_string_equal(r->err, "roboelf-tech: error: 2 USB serial ports "
				    "found: unplug every one but the relay "
				    "board and run again, or name it with "
				    "--serial SERIAL\n");
	assert_non_null(strstr(r->out, "bind-relay: 2 USB serial ports found:\n"
				       "  /dev/ttyTEST0"));
	assert_string_equal(file_text(r->rules), "old rule\n");
	assert_int_equal(run(r, "C3"), 3);
	assert_string_equal(r->err,
			    "roboelf-tech: error: no USB serial port has the "
			    "serial number 'C3' (2 found): plug in that relay "
			    "board and run again\n");
	assert_int_equal(run(r, "A\"1"), 3);
	assert_non_null(strstr(r->err, "serial number 'A\"1' has a character "
				       "not allowed"));
	n_listed = 0;
	assert_int_equal(run(r, NULL), 3);
	assert_string_equal(r->out, "bind-relay: 0 USB serial ports found\n");
	list_rc = GL_ERR_SYS;
	assert_int_equal(run(r, NULL), 3);
	assert_string_equal(r->err, "roboelf-tech: error: cannot list the "
				    "serial ports: Input/output error\n");
	assert_string_equal(file_text(r->rules), "old rule\n");
	/* a directory that does not exist: exit 2, nothing created */
	list_rc = GL_OK;
	listed[0] = relay;
	n_listed = 1;
	snprintf(r->rules + strlen(r->rules), 8, "/x");
	assert_int_equal(run(r, NULL), 2);
	assert_non_null(strstr(r->err, "roboelf-tech: error: cannot write '"));
	assert_non_null(strstr(r->err, "60-roboelf-relay.rules/x': Not a "
				       "directory\n"));
	r->rules[strlen(r->rules) - 2] = '\0';
	assert_string_equal(file_text(r->rules), "old rule\n");
}

/* ---- libserialport's listing, over the wrapped sp_* calls ---- */

struct fake {
	const char *name, *desc, *serial;
	enum sp_transport transport;
	int vid, pid;
};

static const struct fake fakes[] = {
    {"/dev/ttyTEST8", "ttyTEST8", NULL, SP_TRANSPORT_NATIVE, 0, 0},
    {"/dev/ttyTEST0", "FT232R USB UART - A10KXYZ9", "A10KXYZ9", SP_TRANSPORT_USB,
     0x0403, 0x6001},
    {"/dev/rfcomm0", "rfcomm0", NULL, SP_TRANSPORT_BLUETOOTH, 0, 0},
    {"/dev/ttyTEST9", "USB2.0-Serial", NULL, SP_TRANSPORT_USB, 0x1a86, 0x7523},
};
#define N_FAKES (sizeof(fakes) / sizeof(fakes[0]))

static struct sp_port *fake_list_ptrs[N_FAKES + 1];
static int list_fail, n_freed;

static char by_name[512]; /* the last name sp_get_port_by_name had */

enum sp_return __wrap_sp_get_port_by_name(const char *portname,
					  struct sp_port **port_ptr);
void __wrap_sp_free_port(struct sp_port *port);
enum sp_return __wrap_sp_list_ports(struct sp_port ***list_ptr);
void __wrap_sp_free_port_list(struct sp_port **ports);
char *__wrap_sp_get_port_name(const struct sp_port *port);
char *__wrap_sp_get_port_description(const struct sp_port *port);
char *__wrap_sp_get_port_usb_serial(const struct sp_port *port);
enum sp_transport __wrap_sp_get_port_transport(const struct sp_port *port);
enum sp_return __wrap_sp_get_port_usb_vid_pid(const struct sp_port *port,
					      int *usb_vid, int *usb_pid);

static const struct fake *fake_of(const struct sp_port *port)
{
	const struct fake *f = (const struct fake *)(const void *)port;

	assert_true(f >= fakes && f < fakes + N_FAKES);
	return f;
}

/* The port of the fake whose name ends as @portname does (a node in the
 * test's directory stands for /dev/ttyTEST0 ...); else "not found". */
enum sp_return __wrap_sp_get_port_by_name(const char *portname,
					  struct sp_port **port_ptr)
{
	const char *base = strrchr(portname, '/');
	size_t i;

	snprintf(by_name, sizeof(by_name), "%s", portname);
	for (i = 0; base && i < N_FAKES; i++)
		if (!strcmp(strrchr(fakes[i].name, '/'), base)) {
			*port_ptr = (struct sp_port *)(void *)&fakes[i];
			return SP_OK;
		}
	*port_ptr = NULL;
	return SP_ERR_ARG;
}

void __wrap_sp_free_port(struct sp_port *port)
{
	(void)fake_of(port);
	n_freed++;
}

enum sp_return __wrap_sp_list_ports(struct sp_port ***list_ptr)
{
	size_t i;

	if (list_fail) {
		errno = EACCES;
		return SP_ERR_FAIL;
	}
	for (i = 0; i < N_FAKES; i++)
		fake_list_ptrs[i] = (struct sp_port *)(void *)&fakes[i];
	fake_list_ptrs[N_FAKES] = NULL;
	*list_ptr = fake_list_ptrs;
	return SP_OK;
}

void __wrap_sp_free_port_list(struct sp_port **ports)
{
	assert_ptr_equal(ports, fake_list_ptrs);
	n_freed++;
}

char *__wrap_sp_get_port_name(const struct sp_port *port)
{
	return (char *)fake_of(port)->name;
}

char *__wrap_sp_get_port_description(const struct sp_port *port)
{
	return (char *)fake_of(port)->desc;
}

char *__wrap_sp_get_port_usb_serial(const struct sp_port *port)
{
	return (char *)fake_of(port)->serial;
}

enum sp_transport __wrap_sp_get_port_transport(const struct sp_port *port)
{
	return fake_of(port)->transport;
}

enum sp_return __wrap_sp_get_port_usb_vid_pid(const struct sp_port *port,
					      int *usb_vid, int *usb_pid)
{
	const struct fake *f = fake_of(port);

	if (f->transport != SP_TRANSPORT_USB)
		return SP_ERR_ARG;
	*usb_vid = f->vid;
	*usb_pid = f->pid;
	return SP_OK;
}

/* USB ports only, with their ids, serial numbers and descriptions; the
 * list freed; too many, and a failed listing, said. */
static void test_list_sp(void **state)
{
	struct re_bind_port p[4];
	char err[RE_BIND_ERR_MAX];
	size_t n = 99;

	(void)state;
	n_freed = 0;
	assert_int_equal(re_bindrelay_list_sp(p, 4, &n, err, sizeof(err)),
			 GL_OK);
	assert_int_equal(n, 2);
	assert_string_equal(p[0].name, "/dev/ttyTEST0");
	assert_string_equal(p[0].desc, "FT232R USB UART - A10KXYZ9");
	assert_string_equal(p[0].serial, "A10KXYZ9");
	assert_int_equal(p[0].vid, 0x0403);
	assert_int_equal(p[0].pid, 0x6001);
	assert_string_equal(p[1].name, "/dev/ttyTEST9");
	assert_string_equal(p[1].serial, "");
	assert_int_equal(p[1].vid, 0x1a86);
	assert_int_equal(n_freed, 1);
	assert_int_equal(re_bindrelay_list_sp(p, 1, &n, err, sizeof(err)),
			 GL_ERR_OVERFLOW);
	assert_string_equal(err, "more than 1 USB serial ports: unplug every "
				 "one but the relay board and run again");
	assert_int_equal(n_freed, 2);
	list_fail = 1;
	assert_int_equal(re_bindrelay_list_sp(p, 4, &n, err, sizeof(err)),
			 GL_ERR_SYS);
	assert_string_equal(err,
			    "cannot list the serial ports: Permission denied");
	assert_int_equal(n, 0);
	list_fail = 0;
}

/* re_relay_usb_serial(): the node behind a link is asked for (libserialport
 * knows ports by their node's name only); the serial number of a USB port,
 * "" for one without or a port that is not USB; the refusals. */
static void test_usb_serial(void **state)
{
	struct run *r = *state;
	char node[128], link[128], real[4096], buf[RE_BIND_SERIAL_MAX];
	char err[RE_BIND_ERR_MAX], want[512];
	FILE *f;

	snprintf(node, sizeof(node), "%s/ttyTEST0", r->dir);
	snprintf(link, sizeof(link), "%s/roboelf-relay", r->dir);
	f = fopen(node, "w");
	assert_non_null(f);
	fclose(f);
	assert_int_equal(symlink(node, link), 0);
	assert_non_null(realpath(node, real));
	n_freed = 0;
	assert_int_equal(
	    re_relay_usb_serial(link, buf, sizeof(buf), err, sizeof(err)),
	    GL_OK);
	assert_string_equal(by_name, real);
	assert_string_equal(buf, "A10KXYZ9");
	assert_int_equal(n_freed, 1);
	assert_int_equal(re_relay_usb_serial(link, buf, 4, err, sizeof(err)),
			 GL_ERR_RELAY);
	snprintf(want, sizeof(want),
		 "relay '%s': its USB serial number is longer than 3 bytes",
		 link);
	assert_string_equal(err, want);
	assert_int_equal(n_freed, 2);
	assert_int_equal(re_relay_usb_serial("/dev/ttyTEST9", buf, sizeof(buf),
					     err, sizeof(err)),
			 GL_OK);
	assert_string_equal(buf, "");
	assert_int_equal(re_relay_usb_serial("/dev/ttyTEST8", buf, sizeof(buf),
					     err, sizeof(err)),
			 GL_OK);
	assert_string_equal(buf, "");
	assert_int_equal(re_relay_usb_serial("/dev/nothing-here", buf,
					     sizeof(buf), err, sizeof(err)),
			 GL_ERR_RELAY);
	assert_string_equal(by_name, "/dev/nothing-here");
	assert_string_equal(err, "relay '/dev/nothing-here': cannot read its "
				 "USB serial number: not a serial port known "
				 "to libserialport");
	assert_int_equal(n_freed, 4);
	unlink(link);
	unlink(node);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_serial_check),
	    cmocka_unit_test(test_choose_one),
	    cmocka_unit_test(test_choose_wanted),
	    cmocka_unit_test(test_rule_text),
	    cmocka_unit_test(test_verify),
	    cmocka_unit_test_setup_teardown(test_run_serial, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_run_one, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_run_refused, setup, teardown),
	    cmocka_unit_test(test_list_sp),
	    cmocka_unit_test_setup_teardown(test_usb_serial, setup, teardown),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
