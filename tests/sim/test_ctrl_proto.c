/*
 * test_ctrl_proto.c - the host protocol of the simulated DMC-4030 on its
 * handles: ':'/'?' framing per command, the 80-character line, ^R^V, WH,
 * TH, DL/UL with their acknowledgements (and TC 17 while a program runs),
 * QR in the 40x0 layout, unsolicited MG routing with CF and CW 1, IH
 * closing, and BP/BN/BV over a power cycle with #AUTO.
 * Expectations: galil-notes.md sections 1 and 3, DMC command reference.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "ctrl_buf.h"
#include "gl_record.h"
#include "test_ctrl_util.h"

static int setup(void **state)
{
	static struct tplant p;
	int h;

	if (tp_init(&p))
		return -1;
	for (h = 0; h < CTRL_HANDLES; h++)
		ctrl_handle_open(p.c, h);
	tp_step(&p, 1);
	*state = &p;
	return 0;
}

static int teardown(void **state)
{
	tp_free(*state);
	return 0;
}

static void exchange(struct tplant *p, int h, const char *send,
		     const char *want)
{
	char buf[4096];

	tp_send(p, h, send);
	tp_out(p, h, buf, sizeof(buf));
	assert_string_equal(buf, want);
}

/* One terminator per command; data then CR LF then ':'; '?' alone. */
static void test_framing(void **state)
{
	struct tplant *p = *state;

	exchange(p, 0, "MG 1;MG 2\r", " 1.0000\r\n: 2.0000\r\n:");
	exchange(p, 0, "x=1;bad;x=2\r", ":?:");
	exchange(p, 0, "MG x\r\n", " 2.0000\r\n:");
	exchange(p, 0, "\r", ":");
	exchange(p, 0, "TC1\r", " 1 Unrecognized command\r\n:");
	/* a command split over several writes */
	exchange(p, 0, "MG 4", "");
	exchange(p, 0, "2\r", " 42.0000\r\n:");
	exchange(p, 1, "bg\r", "?");
	exchange(p, 1, "TC\r", " 1\r\n:");
}

/*
 * The first reply of a fresh controller that has no text (its reply buffer
 * never held anything): ':' only. tests/fuzz/fuzz_sim_cmd.c found that this
 * path computed NULL + 0 (undefined behaviour) before ctrl_buf_data().
 */
static void test_first_reply_empty(void **state)
{
	struct tplant *p = *state;

	exchange(p, 2, "x=1\r", ":");
	exchange(p, 3, "\r", ":");
	exchange(p, 2, "MG x\r", " 1.0000\r\n:");
}

/* ctrl_buf_data(): never NULL, the unread bytes once there are some. */
static void test_buf_data(void **state)
{
	struct ctrl_buf b = {0};
	uint8_t one;

	(void)state;
	assert_non_null(ctrl_buf_data(&b));
	assert_int_equal(ctrl_buf_pending(&b), 0);
	assert_int_equal(ctrl_buf_puts(&b, "ab"), 0);
	assert_memory_equal(ctrl_buf_data(&b), "ab", 2);
	assert_int_equal(ctrl_buf_take(&b, &one, 1), 1);
	assert_int_equal(one, 'a');
	assert_int_equal(ctrl_buf_pending(&b), 1);
	assert_memory_equal(ctrl_buf_data(&b), "b", 1);
	ctrl_buf_free(&b);
	assert_non_null(ctrl_buf_data(&b));
	assert_int_equal(ctrl_buf_pending(&b), 0);
}

/* More than 80 characters: refused whole, one '?' per command, TC 5. */
static void test_line_limit(void **state)
{
	struct tplant *p = *state;
	char line[128];

	memset(line, ' ', 80);
	memcpy(line + 76, "MG 1\r", 6); /* exactly 80 characters */
	exchange(p, 0, line, " 1.0000\r\n:");
	memset(line, ' ', 90);
	memcpy(line, "x=1;y=2;", 8);
	strcpy(line + 90, "\r");
	exchange(p, 0, line, "???");
	exchange(p, 0, "TC\r", " 5\r\n:");
	exchange(p, 0, "MG 3\r", " 3.0000\r\n:");
}

static void test_identification(void **state)
{
	struct tplant *p = *state;
	char buf[2048];

	exchange(p, 0, "\x12\x16\r", "DMC4030 Rev 1.2h-sim\r\n:");
	exchange(p, 2, "WH\r", "IHC\r\n:");
	exchange(p, 0, "MG _BN\r", " 4242.0000\r\n:");
	exchange(p, 0, "QZ\r", " 3, 52, 26, 36\r\n:");
	ctrl_handle_close(p->c, 5);
	tp_send(p, 0, "TH\r");
	tp_out(p, 0, buf, sizeof(buf));
	assert_non_null(strstr(buf, "CONTROLLER IP ADDRESS"));
	assert_non_null(strstr(buf, "IHA TCP PORT"));
	assert_non_null(strstr(buf, "IHF AVAILABLE"));
	exchange(p, 0, "MG _IHA2,_IHF2\r", " 2.0000 0.0000\r\n:");
}

/* CO: extended I/O configuration 0..15 stored and read back; out of range
 * refused with TC 6 (number out of range). */
static void test_extended_io(void **state)
{
	struct tplant *p = *state;

	exchange(p, 0, "CO 3\r", ":");
	exchange(p, 0, "MG _CO\r", " 3.0000\r\n:");
	exchange(p, 0, "CO 0;CO ?\r", ": 0\r\n:");
	exchange(p, 0, "CO 16\r", "?");
	exchange(p, 0, "TC\r", " 6\r\n:");
}

static const char prog_text[] = "#AUTO\r"
				"n=0\r"
				"#LOOP;n=n+1;WT 10\r"
				"JP #LOOP\r"
				"EN\r";

/* DL: silent, then "::" after '\'; UL gives it back, CR LF, ^Z, ':'. */
static void test_dl_ul(void **state)
{
	struct tplant *p = *state;
	char want[512];

	exchange(p, 0, "DL\r", "");
	exchange(p, 0, prog_text, "");
	exchange(p, 0, "\\", "::");
	snprintf(want, sizeof(want),
		 "#AUTO\r\nn=0\r\n#LOOP;n=n+1;WT 10\r\nJP #LOOP\r\nEN\r\n"
		 "\x1a:");
	exchange(p, 0, "UL\r", want);
	/* Ctrl-Z also ends a download; CR LF line ends are fine */
	exchange(p, 1, "DL\r#A\r\nEN\r\n\x1a", "::");
	exchange(p, 1, "UL\r", "#A\r\nEN\r\n\x1a:");
	exchange(p, 1, "LS\r", "0 #A\r\n1 EN\r\n:");
	/* an empty download erases the program */
	exchange(p, 1, "DL\r\\", "::");
	exchange(p, 1, "UL\r", "\x1a:");
}

/* DL while a thread runs: '?' and TC 17 (HX first). */
static void test_dl_refused_running(void **state)
{
	struct tplant *p = *state;

	exchange(p, 0, "DL\r#AUTO\r#L;WT 10;JP #L\r\\", "::");
	exchange(p, 0, "XQ #AUTO\r", ":");
	tp_step(p, 5);
	exchange(p, 0, "DL\r", "?");
	exchange(p, 0, "TC1\r",
		 " 17 ED, BN and DL not valid while program running\r\n:");
	exchange(p, 0, "HX;DL\r#B\rEN\r\\", ":::");
	exchange(p, 0, "UL\r", "#B\r\nEN\r\n\x1a:");
}

/* A download before the first sample (galil-sim busy at start): the
 * program is loaded, and its #AUTO does not start by itself afterwards. */
static void test_dl_before_first_sample(void **state)
{
	struct tplant p;

	(void)state;
	assert_int_equal(tp_init(&p), 0);
	ctrl_handle_open(p.c, 0);
	exchange(&p, 0, "DL\r", "");
	exchange(&p, 0, prog_text, "");
	exchange(&p, 0, "\\", "::");
	tp_step(&p, 5);
	exchange(&p, 0, "MG _XQ0\r", " -1.0000\r\n:");
	exchange(&p, 0, "XQ #AUTO,0\r", ":");
	tp_free(&p);
}

/* A bad line answers '?' at once; the download is refused and erased. */
static void test_dl_bad(void **state)
{
	struct tplant *p = *state;
	char line[100];
	int i;

	exchange(p, 0, "DL\r#A\rEN\r\\", "::");
	memset(line, 'x', 85);
	strcpy(line + 85, "\r");
	exchange(p, 0, "DL\r#B\r", "");
	exchange(p, 0, line, "?");
	exchange(p, 0, "EN\r\\", ":?");
	exchange(p, 0, "TC\r", " 60\r\n:");
	exchange(p, 0, "UL\r", "\x1a:");
	/* duplicate and bad labels: refused at the end, TC 61 */
	exchange(p, 0, "DL\r#A\r#A\r\\", ":?");
	exchange(p, 0, "TC\r", " 61\r\n:");
	exchange(p, 0, "DL\r#9A\r\\", ":?");
	exchange(p, 0, "DL\r#TOOLONGX\r\\", ":?");
	exchange(p, 0, "DL\r#_ok\r\\", ":?");
	exchange(p, 0, "TC\r", " 61\r\n:");
	/* 4000 lines fit, line 4001 does not */
	exchange(p, 0, "DL\r", "");
	for (i = 0; i < 4000; i++)
		exchange(p, 0, "NO\r", "");
	exchange(p, 0, "\\", "::");
	exchange(p, 0, "MG _DL\r", " 510.0000\r\n:");
	exchange(p, 0, "DL\r", "");
	for (i = 0; i < 4000; i++)
		exchange(p, 0, "NO\r", "");
	exchange(p, 0, "NO\r", "?");
	exchange(p, 0, "\\", ":?");
	exchange(p, 0, "TC\r", " 60\r\n:");
}

/*
 * Unsolicited output goes to the CF handle only; CW 1 sets the high bit of
 * every unsolicited byte, CW 2 does not; replies are never marked.
 */
static void test_unsolicited(void **state)
{
	struct tplant *p = *state;
	char buf[256];
	size_t n, i;

	exchange(p, 0, "DL\r#A\rMG \"hi\",n\rEN\r\\", "::");
	exchange(p, 0, "n=7;CF B;CW 1;XQ #A\r", "::::");
	tp_step(p, 2);
	assert_int_equal(tp_out(p, 0, buf, sizeof(buf)), 0);
	n = tp_out(p, 1, buf, sizeof(buf));
	assert_int_equal(n, strlen("hi 7.0000\r\n"));
	for (i = 0; i < n; i++)
		assert_int_equal((uint8_t)buf[i],
				 (uint8_t)("hi 7.0000\r\n"[i] | 0x80));
	exchange(p, 0, "CW 2;XQ #A\r", "::");
	tp_step(p, 2);
	exchange(p, 1, "", "hi 7.0000\r\n");
	/* {Ex} overrides CF; MG from a host with {Ex} goes there too */
	exchange(p, 0, "MG {EC} \"to C\"\r", ":");
	exchange(p, 2, "", "to C\r\n");
	exchange(p, 0, "MG _CF,_CW\r", " 66.0000 2.0000\r\n:");
}

/* CW ,0: a full unsolicited FIFO holds the thread; CW ,1 drops instead. */
static void test_unsolicited_full(void **state)
{
	struct tplant *p = *state;
	char buf[4096];
	size_t n;

	exchange(p, 0,
		 "DL\r#A;i=i+1;MG \"0123456789012345678901234567890\";"
		 "JP #A\r\\",
		 "::");
	exchange(p, 0, "i=0;CF B;XQ #A\r", ":::");
	tp_step(p, 20);
	n = tp_out(p, 1, buf, sizeof(buf));
	assert_true(n <= 1024);
	/* the thread waited: fewer loops than 20 samples * 16 lines */
	assert_true(tp_mg(p, "i") < 40);
	exchange(p, 0, "CW ,1\r", ":");
	tp_step(p, 20);
	assert_true(tp_mg(p, "i") > 300);
	exchange(p, 0, "HX\r", ":");
}

/* QR: the 190-byte 40x0 record for 3 axes, then ':'. */
static void test_qr(void **state)
{
	struct tplant *p = *state;
	uint8_t buf[512];
	struct gl_record r;
	size_t n;

	exchange(p, 0, "DL\r#A;WT 1000;EN\r\\", "::");
	exchange(p, 0, "ZAA=123;ZAB=-4;DP 10,20,30;XQ #A,2;bad\r", "::::?");
	tp_step(p, 1);
	tp_send(p, 0, "QR\r");
	n = ctrl_output(p->c, 0, buf, sizeof(buf));
	assert_int_equal(n, 190 + 1);
	assert_int_equal(buf[190], ':');
	assert_int_equal(gl_record_decode(buf, 190, GL_LAYOUT_4000, 3, &r),
			 GL_OK);
	assert_int_equal(r.axis[0].za, 123);
	assert_int_equal(r.axis[1].za, -4);
	assert_int_equal(r.axis[2].motor_pos, 30);
	assert_int_equal(r.threads, 1u << 2);
	assert_int_equal(r.error_code, 1);
	assert_int_equal(r.handles[0], 2);
	assert_true(r.axis[0].status & GL_AXST_MOTOR_OFF);
	assert_true(r.axis[0].switches & GL_AXSW_FLS);
	exchange(p, 0, "HX\r", ":");
}

/* IHT=>-3 closes every other handle; IHS=>-3 the sender. */
static void test_ih_close(void **state)
{
	struct tplant *p = *state;
	int h;

	exchange(p, 0, "IHT=>-3\r", ":");
	assert_false(ctrl_handle_close_wanted(p->c, 0));
	for (h = 1; h < CTRL_HANDLES; h++)
		assert_true(ctrl_handle_close_wanted(p->c, h));
	exchange(p, 0, "IHS=>-3\r", ":");
	assert_true(ctrl_handle_close_wanted(p->c, 0));
	exchange(p, 1, "IHA=192,168,0,1\r", "?");
}

/* BP/BN/BV survive a power cycle, RAM does not; #AUTO runs at power-up. */
static void test_power_cycle(void **state)
{
	struct tplant *p = *state;

	exchange(p, 0, "DL\r", "");
	exchange(p, 0, prog_text, "");
	exchange(p, 0, "\\", "::");
	exchange(p, 0, "KP 10,,2;BN;keep=5;BV;lost=1;BP\r", "::::::");
	exchange(p, 0, "XQ #AUTO\r", ":");
	tp_step(p, 5);
	exchange(p, 0, "BP\r", "?"); /* TC 17 while running */
	ctrl_power_cycle(p->c);
	assert_true(ctrl_handle_close_wanted(p->c, 0));
	ctrl_handle_close(p->c, 0);
	ctrl_handle_open(p->c, 0);
	tp_step(p, 25);
	assert_int_equal(ctrl_threads(p->c), 1u);
	assert_true(tp_has_event(p, "#AUTO started in thread 0"));
	exchange(p, 0, "MG n>=2,keep\r", " 1.0000 5.0000\r\n:");
	exchange(p, 0, "MG lost\r", "?");
	exchange(p, 0, "KP ?,?,?\r", " 10.0000, 6.0000, 2.0000\r\n:");
	exchange(p, 0, "MG _TIME\r", "?");
	exchange(p, 0, "MG TIME<30\r", " 1.0000\r\n:");
	/* without BP a new program is lost at the next power cycle */
	exchange(p, 0, "HX;DL\r#B\rEN\r\\", ":::");
	ctrl_power_cycle(p->c);
	ctrl_handle_close(p->c, 0);
	ctrl_handle_open(p->c, 0);
	exchange(p, 0, "UL\r",
		 "#AUTO\r\nn=0\r\n#LOOP;n=n+1;WT 10\r\n"
		 "JP #LOOP\r\nEN\r\n\x1a:");
}

/* A lost TCP handle: #TCPERR with _IA4 = the handle, TC 123. */
static void test_tcperr(void **state)
{
	struct tplant *p = *state;

	exchange(p, 0, "DL\r#A;WT 1000;EN\r#TCPERR\rh=_IA4;c=_TC\rRE1\r\\",
		 "::");
	exchange(p, 0, "h=-1;c=0;XQ #A\r", ":::");
	tp_step(p, 2);
	ctrl_handle_lost(p->c, 3);
	tp_step(p, 2);
	exchange(p, 0, "MG h,c,_IHD2\r", " 3.0000 123.0000 0.0000\r\n:");
	assert_int_equal(ctrl_threads(p->c), 1u); /* RE1: still in WT */
	exchange(p, 0, "HX\r", ":");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_framing, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_first_reply_empty, setup,
					    teardown),
	    cmocka_unit_test(test_buf_data),
	    cmocka_unit_test_setup_teardown(test_line_limit, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_identification, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_extended_io, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_dl_ul, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_dl_refused_running, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_dl_bad, setup, teardown),
	    cmocka_unit_test(test_dl_before_first_sample),
	    cmocka_unit_test_setup_teardown(test_unsolicited, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_unsolicited_full, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_qr, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_ih_close, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_power_cycle, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_tcperr, setup, teardown),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
