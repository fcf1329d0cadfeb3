/*
 * test_ctrl_lang.c - the DMC language of the simulated controller:
 * expressions (left to right), numbers and formats, variables and arrays,
 * IF nesting, JS parameters, labels with '_', WT/AT timing, threads and _XQn,
 * #CMDERR with _TC/_ED, and the TC codes of bad commands. Expected values come
 * from the DMC-40x0 command reference examples (galil-notes.md 4.2, MG,
 * @functions).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "test_ctrl_util.h"

static int setup(void **state)
{
	static struct tplant p;

	if (tp_init(&p))
		return -1;
	tp_step(&p, 1);
	*state = &p;
	return 0;
}

static int teardown(void **state)
{
	tp_free(*state);
	return 0;
}

static void expect_reply(struct tplant *p, const char *line, const char *want)
{
	char resp[512];

	assert_int_equal(tp_cmd(p, line, resp, sizeof(resp)), GL_OK);
	assert_string_equal(resp, want);
}

static void expect_error(struct tplant *p, const char *line, int tc)
{
	char resp[512];

	assert_int_equal(tp_cmd(p, line, resp, sizeof(resp)), GL_ERR_CTRL);
	assert_string_equal(resp, "?");
	assert_int_equal(tp_tc(p), tc);
}

/* "MG 1+2*3" prints 9 (no precedence), parentheses override. */
static void test_left_to_right(void **state)
{
	struct tplant *p = *state;

	expect_reply(p, "MG 1+2*3", " 9.0000\r\n");
	expect_reply(p, "MG 1+(2*3)", " 7.0000\r\n");
	expect_reply(p, "MG 10*30-60/30", " 8.0000\r\n");
	expect_reply(p, "MG ((10*30)+(60/30))", " 302.0000\r\n");
	expect_reply(p, "var1=$1F;var2=$F", ":");
	expect_reply(p, "MG var1&var2/$10", " 0.9375\r\n");
	expect_reply(p, "MG var1&(var2/$10)", " 0.0000\r\n");
	expect_reply(p, "MG (1<2)+(2<=2)+(3>=4)+(1<>1)+(5=5)", " 3.0000\r\n");
	expect_reply(p, "MG 7%3", " 1.0000\r\n");
	expect_reply(p, "MG -3+5", " 2.0000\r\n");
	expect_reply(p, "MG 2*-3", " -6.0000\r\n");
}

/* 32.16 fixed point: 1/3 is $0.5555; decimal output rounds to 4 places. */
static void test_fixed_point(void **state)
{
	struct tplant *p = *state;

	expect_reply(p, "MG (1/3){$1.4}", "$0.5555\r\n");
	expect_reply(p, "MG 2/3", " 0.6667\r\n");
	expect_reply(p, "MG -1/3", " -0.3333\r\n");
	expect_reply(p, "MG @ABS[-2147483647]", " 2147483647.0000\r\n");
	expect_reply(p, "MG $7FFFFFFF.FFFF{$8.4}", "$7FFFFFFF.FFFF\r\n");
	expect_reply(p, "MG $FFFFFFFF", " -1.0000\r\n");
	expect_error(p, "MG 1/0", 6);
}

static void test_functions(void **state)
{
	struct tplant *p = *state;

	expect_reply(p, "MG @INT[1.2],@INT[-2.4]", " 1.0000 -2.0000\r\n");
	expect_reply(p, "MG @FRAC[1.2],@FRAC[-2.4]", " 0.2000 -0.4000\r\n");
	expect_reply(p, "MG @RND[5.5],@RND[-5.5],@RND[-5.7]",
		     " 6.0000 -5.0000 -6.0000\r\n");
	expect_reply(p, "MG @SQR[2],@SQR[-2]", " 1.4142 1.4142\r\n");
	expect_reply(p, "MG @SIN[90],@COS[180]", " 1.0000 -1.0000\r\n");
	expect_reply(p, "MG @ATAN[10]", " 84.2894\r\n");
	expect_reply(p, "MG {$8.0} @COM[0]", "$FFFFFFFF\r\n");
	expect_reply(p, "MG @FLOT[2.5] {$8.0}", "$40200000\r\n");
	expect_reply(p, "MG @REAL[$40200000]", " 2.5000\r\n");
	p->in.inputs = 0x5; /* inputs 1 and 3 high */
	p->in.an_v[1] = 1.25;
	tp_step(p, 1);
	expect_reply(p, "MG @IN[1],@IN[2],@IN[3],@AN[2]",
		     " 1.0000 0.0000 1.0000 1.2500\r\n");
	expect_reply(p, "SB 2;MG @OUT[2];CB 2;MG @OUT[2]",
		     ": 1.0000\r\n:: 0.0000\r\n");
	expect_error(p, "MG @FOO[1]", 57);
	expect_error(p, "MG @ABS 1", 55);
	expect_error(p, "MG (1+2", 59);
}

/* MG formatters of the command reference. */
static void test_mg_formats(void **state)
{
	struct tplant *p = *state;
	char resp[64];

	expect_reply(p, "RESULT=4.1", "");
	expect_reply(p, "MG \"The Final Value is\", RESULT {F5.2}",
		     "The Final Value is 00004.10\r\n");
	expect_reply(p, "MG \"in \",123{Z10.0},\" days\"", "in  123 days\r\n");
	expect_reply(p, "MG {Z5.0} 7, 8", " 7 8\r\n");
	expect_reply(p, "MG 123{F2.1}", " 99.9\r\n");
	expect_reply(p, "name=\"SAT\";MG name{S3}", ":SAT\r\n");
	expect_reply(p, "MG {^65},{^66}", "AB\r\n");
	expect_reply(p, "MG \"no newline\"{N}", "no newline");
	expect_reply(p, "MG 31{$4.0}", "$001F\r\n");
	expect_error(p, "MG 1{F5.2", 53);
	expect_error(p, "MG \"open", 52);
	assert_int_equal(tp_cmd(p, "MG \"a;b\"", resp, sizeof(resp)), GL_OK);
	assert_string_equal(resp, "a;b\r\n");
}

static void test_variables(void **state)
{
	struct tplant *p = *state;
	double v;

	expect_reply(p, "x=5", "");
	expect_reply(p, "x=?", " 5.0000\r\n");
	expect_reply(p, "x=", " 5.0000\r\n");
	expect_reply(p, "apple = 10-4", "");
	expect_reply(p, "MG apple - 1", " 5.0000\r\n");
	expect_reply(p, "Abc=1;abc=2;MG Abc,abc",
		     "::\x20"
		     "1.0000 2.0000\r\n");
	expect_reply(p, "CD0=7;MG CD0", ": 7.0000\r\n");
	expect_error(p, "MG nosuch", 1);
	expect_error(p, "abcdefghi=1", 9);
	expect_error(p, "TIME=1", 1);
	assert_int_equal(ctrl_get_var(p->c, "x", &v), GL_OK);
	assert_true(v == 5);
	assert_int_equal(ctrl_set_var(p->c, "y", 2.5), GL_OK);
	expect_reply(p, "MG y*2", " 5.0000\r\n");
	assert_int_equal(ctrl_get_var(p->c, "nosuch", &v), GL_ERR_NOENT);
}

static void test_arrays(void **state)
{
	struct tplant *p = *state;
	double v;

	expect_reply(p, "DM arr[5],b2[3]", "");
	expect_reply(p, "arr[0]=3;arr[4]=arr[0]*2", ":");
	expect_reply(p, "MG arr[4],arr[-1],b2[-1]",
		     " 6.0000 5.0000 3.0000\r\n");
	expect_reply(p, "arr[1]=?", " 0.0000\r\n");
	expect_error(p, "arr[5]=1", 56);
	expect_error(p, "MG arr[5]", 56);
	expect_error(p, "MG nope[0]", 57);
	expect_error(p, "DM big[30000]", 6);
	assert_int_equal(ctrl_get_var(p->c, "arr[4]", &v), GL_OK);
	assert_true(v == 6);
	assert_int_equal(ctrl_get_var(p->c, "arr[9]", &v), GL_ERR_NOENT);
	expect_reply(p, "DA arr[]", "");
	expect_error(p, "MG arr[0]", 57);
}

/* DM of an array that exists: the same size changes nothing (values
 * kept), another size is refused with TC 57 and the array stays; a program
 * gets the same error. DA first, then DM, re-dimensions. */
static void test_dm_existing_array(void **state)
{
	struct tplant *p = *state;
	char resp[128];

	expect_reply(p, "DM a[5];a[0]=7;MG a[0],a[-1],_DM",
		     ":: 7.0000 5.0000 23995.0000\r\n");
	expect_error(p, "DM a[5]", 57); /* even the same size */
	expect_error(p, "DM a[8]", 57);
	assert_int_equal(tp_cmd(p, "DM a[6]", resp, sizeof(resp)), GL_ERR_CTRL);
	assert_int_equal(tp_cmd(p, "TC 1", resp, sizeof(resp)), GL_OK);
	assert_string_equal(resp, " 57 Bad function or array\r\n");
	expect_reply(p, "MG a[0],a[-1],_DM,_DA",
		     " 7.0000 5.0000 23995.0000 29.0000\r\n");
	expect_reply(p, "DA a[];DM a[8];MG a[0],a[-1],_DM",
		     ":: 0.0000 8.0000 23992.0000\r\n");
	assert_int_equal(tp_load(p, "#P\rDA a[]\rDM a[8]\rDM a[9]\rok=1\rEN\r"),
			 GL_OK);
	expect_reply(p, "ok=0;XQ #P", ":");
	tp_step(p, 5);
	assert_true(tp_has_event(p, "program error thread 0 line 3 TC 57 Bad "
				    "function or array"));
	expect_reply(p, "MG ok,a[-1]", " 0.0000 8.0000\r\n");
}

/* DA as the DMC-40x0 reference writes it: name[] or name[0] for an array,
 * *[] or *[0] for every array, * for every variable; DA ? the free array
 * slots. */
static void test_da_forms(void **state)
{
	struct tplant *p = *state;

	expect_reply(p, "DM Cars[40],Salesmen[50],keep[2];Total=70", ":");
	expect_reply(p, "DA ?", " 27\r\n");
	expect_reply(p, "DA Cars[0],Salesmen[],Total;MG _DA,_DM,_UL",
		     ": 29.0000 23998.0000 510.0000\r\n");
	expect_error(p, "MG Cars[0]", 57);
	expect_error(p, "MG Total", 1);
	expect_reply(p, "MG keep[-1]", " 2.0000\r\n");
	expect_reply(p, "DM b[3],c[4];v=1;DA *[0];MG _DA,_DM,v",
		     "::: 30.0000 24000.0000 1.0000\r\n");
	expect_reply(p, "DM b[3];DA *;MG _DA,_UL,b[-1]",
		     ":: 29.0000 510.0000 3.0000\r\n");
	expect_reply(p, "DA*[];DA ?", ": 30\r\n");
	expect_error(p, "DA nope[]", 57);
	expect_error(p, "DA nope", 9);
	expect_reply(p, "DM b[3]", "");
	expect_error(p, "DA b[0", 55);
	expect_error(p, "DA b[,c[]", 55);
	expect_reply(p, "MG b[-1]", " 3.0000\r\n");
}

/* Lower case commands, unknown commands and operands used as commands. */
static void test_bad_commands(void **state)
{
	struct tplant *p = *state;
	char resp[64];

	expect_error(p, "bg", 1);
	expect_error(p, "tp", 1);
	expect_error(p, "ZZ", 1);
	expect_error(p, "_TPA", 1);
	expect_error(p, "#LABEL", 1);
	expect_error(p, "JP #A", 2); /* program only */
	expect_error(p, "WT 10", 2);
	/* TC1 gives code and text, and reading TC clears it */
	assert_int_equal(tp_cmd(p, "bg", resp, sizeof(resp)), GL_ERR_CTRL);
	expect_reply(p, "TC1", " 1 Unrecognized command\r\n");
	expect_reply(p, "TC1", " 0\r\n");
	expect_reply(p, "NO this is fine", "");
	expect_reply(p, "' so is this", "");
}

static void load_run(struct tplant *p, const char *prog, const char *xq,
		     int samples)
{
	char resp[64];

	assert_int_equal(tp_load(p, prog), GL_OK);
	assert_int_equal(tp_cmd(p, xq, resp, sizeof(resp)), GL_OK);
	tp_step(p, samples);
}

static void test_nested_if(void **state)
{
	struct tplant *p = *state;
	const char *prog = "#A\r"
			   "r=0\r"
			   "IF (a=1)\r"
			   " IF (b=1)\r"
			   "  r=11\r"
			   " ELSE\r"
			   "  r=10\r"
			   " ENDIF\r"
			   "ELSE\r"
			   " IF (b=1);r=1;ELSE;r=0.5;ENDIF\r"
			   "ENDIF\r"
			   "EN\r";
	static const double want[4] = {0.5, 1, 10, 11};
	char line[32];
	int i;

	for (i = 0; i < 4; i++) {
		snprintf(line, sizeof(line), "a=%d;b=%d", i >> 1, i & 1);
		expect_reply(p, line, ":");
		load_run(p, prog, "XQ #A", 5);
		assert_true(tp_mg(p, "r") == want[i]);
		assert_int_equal(ctrl_threads(p->c), 0);
	}
}

/* An IF without ENDIF is TC 63 when the condition is false. */
static void test_if_without_endif(void **state)
{
	struct tplant *p = *state;

	load_run(p, "#A\rIF (0)\rx=1\rEN\r", "XQ #A", 5);
	assert_int_equal(tp_tc(p), 63);
	assert_true(tp_has_event(p, "line 1 TC 63"));
}

/* JS #L(args): ^a..^h, return value with EN ,,v in _JS, &var by ref. */
static void test_js_params(void **state)
{
	struct tplant *p = *state;
	const char *prog = "#ADD\r"
			   "JS#SUM(1,2,3,4,5,6,7,8)\r"
			   "s=_JS\r"
			   "v=9\r"
			   "JS #SQ2(&v)\r"
			   "JS #SQ(3),(v>1)\r"
			   "q=_JS\r"
			   "JS #SQ(5),(v<1)\r"
			   "EN\r"
			   "#SUM\r"
			   "EN,,^a+^b+^c+^d+^e+^f+^g+^h\r"
			   "#SQ\r"
			   "EN ,,(^a*^a)\r"
			   "#SQ2\r"
			   "^a=^a*^a\r"
			   "EN\r";

	load_run(p, prog, "XQ #ADD", 10);
	assert_int_equal(ctrl_threads(p->c), 0);
	assert_true(tp_mg(p, "s") == 36);
	assert_true(tp_mg(p, "v") == 81);
	assert_true(tp_mg(p, "q") == 9);
}

/* Labels with '_' download and run on the DMC-40x0 (docs/galil-sim.md,
 * "Labels with '_'"): a subroutine and a jump target, called and taken. */
static void test_underscore_labels(void **state)
{
	struct tplant *p = *state;
	const char *prog = "#run_it\r"
			   "ecode=2\r"
			   "JS #error_h(ecode)\r"
			   "ret=_JS\r"
			   "JP #done_x,(code=20)\r"
			   "code=-1\r"
			   "#done_x\r"
			   "EN\r"
			   "#error_h\r"
			   "code=^a*10\r"
			   "EN ,,code+1\r";

	load_run(p, prog, "XQ #run_it", 10);
	assert_int_equal(ctrl_threads(p->c), 0);
	assert_int_equal(tp_tc(p), 0);
	assert_true(tp_mg(p, "code") == 20);
	assert_true(tp_mg(p, "ret") == 21);
}

/* JS deeper than 16 levels is TC 12. */
static void test_js_depth(void **state)
{
	struct tplant *p = *state;

	load_run(p, "#R\rn=n+1\rJS #R\rEN\r", "n=0;XQ #R", 100);
	assert_int_equal(tp_tc(p), 12);
	assert_true(tp_mg(p, "n") == 17);
}

/* WT n holds the thread n samples (TM 1000: 1 sample = 1 ms). */
static void test_wt_timing(void **state)
{
	struct tplant *p = *state;

	load_run(p, "#A\rt0=TIME\rWT 10\rt1=TIME\rWT 5,1\rt2=TIME\rEN\r",
		 "XQ #A", 30);
	assert_true(tp_mg(p, "t1-t0") == 10);
	assert_true(tp_mg(p, "t2-t1") == 5);
}

/* AT -n: n ms after the reference, which then moves on by n (no drift). */
static void test_at_timing(void **state)
{
	struct tplant *p = *state;
	const char *prog = "#A\r"
			   "DM t[6];i=0\r"
			   "AT 0;t0=TIME\r"
			   "#L\r"
			   "AT -20\r"
			   "t[i]=TIME-t0;i=i+1\r"
			   "WT 7\r" /* work inside the period */
			   "JP #L,i<5\r"
			   "AT 150\r" /* 150 from the reference (100) */
			   "t[5]=TIME-t0\r"
			   "EN\r";
	char name[16];
	int i;

	load_run(p, prog, "XQ #A", 300);
	assert_int_equal(ctrl_threads(p->c), 0);
	for (i = 0; i < 5; i++) {
		snprintf(name, sizeof(name), "t[%d]", i);
		assert_true(tp_mg(p, name) == 20 * (i + 1));
	}
	assert_true(tp_mg(p, "t[5]") == 250);
}

/* XQ starts a thread, _XQn is its line (-1 when stopped), HX halts it. */
static void test_threads(void **state)
{
	struct tplant *p = *state;
	const char *prog = "EN\r"
			   "#A\r"
			   "WT 1000\r"
			   "EN\r"
			   "#B;n=n+1;JP #B\r";
	char resp[64];

	load_run(p, prog, "n=0;XQ #A,1", 2);
	assert_int_equal(ctrl_threads(p->c), 1u << 1);
	assert_true(tp_mg(p, "_XQ1") == 2);
	assert_true(tp_mg(p, "_XQ0") == -1);
	assert_true(tp_mg(p, "_HX1") == 2); /* at a trippoint */
	expect_error(p, "XQ #A,1", 19);
	expect_reply(p, "HX1", "");
	assert_true(tp_mg(p, "_XQ1") == -1);
	assert_true(tp_has_event(p, "thread 1 stopped: halted by HX"));
	/* bare XQ runs line 0: the program's first statement EN */
	expect_reply(p, "XQ", "");
	tp_step(p, 1);
	assert_int_equal(ctrl_threads(p->c), 0);
	expect_error(p, "XQ #NOPE", 10);
	expect_error(p, "XQ #A,8", 6);
	assert_int_equal(tp_cmd(p, "XQ #B,3", resp, sizeof(resp)), GL_OK);
	assert_true(tp_mg(p, "_NO") == 8);
	expect_reply(p, "HX", "");
	assert_int_equal(ctrl_threads(p->c), 0);
}

/*
 * Timing model: one-line loops; one thread alone gets all 16 lines of a
 * sample, two threads share them.
 */
static void test_line_budget(void **state)
{
	struct tplant *p = *state;
	const char *prog = "#A;a=a+1;JP #A\r#B;b=b+1;JP #B\r";

	load_run(p, prog, "a=0;b=0;XQ #A,0", 10);
	assert_true(tp_mg(p, "a") == 160);
	expect_reply(p, "HX;a=0;XQ #A,0;XQ #B,1", ":::");
	tp_step(p, 10);
	assert_true(tp_mg(p, "a") == 80);
	assert_true(tp_mg(p, "b") == 80);
	expect_reply(p, "HX", "");
}

/*
 * #CMDERR: an error in thread 1 halts thread 1 and runs #CMDERR in thread
 * 0 with _TC, _ED (line) and _ED1 (thread); EN returns to thread 0.
 */
static void test_cmderr(void **state)
{
	struct tplant *p = *state;
	const char *prog = "#MAIN\r"	      /* 0 */
			   "XQ #ERR,1\r"      /* 1 */
			   "#LOOP;k=k+1\r"    /* 2 */
			   "WT 10;JP #LOOP\r" /* 3 */
			   "#ERR\r"	      /* 4 */
			   "WT 5\r"	      /* 5 */
			   "XX123\r"	      /* 6: invalid command */
			   "EN\r"	      /* 7 */
			   "#CMDERR\r"	      /* 8 */
			   "tc=_TC;ed=_ED;th=_ED1;n=n+1\r"
			   "EN\r";

	load_run(p, prog, "k=0;n=0;XQ #MAIN", 40);
	assert_true(tp_mg(p, "tc") == 1);
	assert_true(tp_mg(p, "ed") == 6);
	assert_true(tp_mg(p, "th") == 1);
	assert_true(tp_mg(p, "n") == 1);
	assert_int_equal(ctrl_threads(p->c), 1u); /* thread 1 halted */
	assert_true(tp_mg(p, "k") >= 3);	  /* thread 0 goes on */
	assert_true(tp_has_event(p, "program error thread 1 line 6 TC 1"));
	expect_reply(p, "HX", "");
}

/* An error in thread 0 with #CMDERR: EN goes on after the failing command. */
static void test_cmderr_thread0(void **state)
{
	struct tplant *p = *state;
	const char *prog = "#A\r"
			   "a=1;MG nosuch;a=2\r"
			   "a=3\r"
			   "EN\r"
			   "#CMDERR\r"
			   "e=_ED;c=_TC\r"
			   "EN\r";

	load_run(p, prog, "XQ #A", 10);
	assert_true(tp_mg(p, "a") == 3);
	assert_true(tp_mg(p, "e") == 1);
	assert_true(tp_mg(p, "c") == 1);
	assert_int_equal(ctrl_threads(p->c), 0);
}

/* Without #CMDERR an error stops every thread and is reported. */
static void test_error_stops_all(void **state)
{
	struct tplant *p = *state;
	const char *prog = "#A\rXQ #B,1\rWT 1000\rEN\r#B\rWT 5\rJP #NOPE\rEN\r";
	uint8_t buf[128];
	size_t n;

	load_run(p, prog, "CF S;XQ #A", 20);
	assert_int_equal(ctrl_threads(p->c), 0);
	assert_int_equal(tp_tc(p), 10);
	assert_true(tp_mg(p, "_ED") == 6);
	assert_true(tp_has_event(p, "thread 0 stopped: error TC 10 at line 6"));
	n = ctrl_serial_output(p->c, buf, sizeof(buf) - 1);
	buf[n] = '\0';
	assert_string_equal((char *)buf, "?6 JP #NOPE\r\n");
}

/* Malformed statements fail with their line, never silently. */
static void test_error_lines(void **state)
{
	struct tplant *p = *state;
	static const struct {
		const char *stmt;
		int tc;
	} cases[] = {
	    {"x=(1+2", 59},    {"x=arr[1]", 57}, {"x=1+", 1},
	    {"MG \"abc", 52},  {"JP 9999", 11},	 {"ELSE", 63},
	    {"EN 1,2,3,4", 4}, {"DM q[0]", 6},	 {"x=\"TOOLONG\"", 52},
	    {"^z=1", 1},       {"SHD", 6},	 {"PR 1,2,3,4", 6},
	};
	char prog[128];
	size_t i;

	for (i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		snprintf(prog, sizeof(prog), "#A\rNO\r%s\rEN\r", cases[i].stmt);
		load_run(p, prog, "XQ #A", 5);
		assert_int_equal(ctrl_threads(p->c), 0);
		assert_int_equal(tp_tc(p), cases[i].tc);
		assert_true(tp_mg(p, "_ED") == 2);
	}
}

/*
 * EN1 at the end of #CMDERR restores the trippoint thread 0 was waiting
 * in (WT 100 runs to its end); EN clears it (thread 0 goes on at once).
 */
static void test_trippoint_restore(void **state)
{
	struct tplant *p = *state;
	static const char fmt[] = "#A\r"
				  "XQ #B,1\r"
				  "t0=TIME;WT 100;t1=TIME\r"
				  "EN\r"
				  "#B;WT 5;XX\r"
				  "#CMDERR\r"
				  "%s\r";
	char prog[128];

	snprintf(prog, sizeof(prog), fmt, "EN1");
	load_run(p, prog, "XQ #A", 150);
	assert_true(tp_mg(p, "t1-t0") == 100);
	snprintf(prog, sizeof(prog), fmt, "EN");
	load_run(p, prog, "XQ #A", 150);
	assert_true(tp_mg(p, "t1-t0") >= 5);
	assert_true(tp_mg(p, "t1-t0") <= 7);
}

/* ZS clears the stack so an error routine can jump instead of return. */
static void test_zs(void **state)
{
	struct tplant *p = *state;
	const char *prog = "#A\r"
			   "JS #S\r"
			   "EN\r"
			   "#S;MG nosuch;EN\r"
			   "#CMDERR\r"
			   "d=_ZS0;ZS;JP #GO\r"
			   "#GO\r"
			   "z=_ZS0;done=1\r"
			   "EN\r";

	load_run(p, prog, "done=0;XQ #A", 10);
	assert_true(tp_mg(p, "d") == 2); /* JS + #CMDERR */
	assert_true(tp_mg(p, "z") == 0);
	assert_true(tp_mg(p, "done") == 1);
	assert_int_equal(ctrl_threads(p->c), 0);
}

/* ~a axis designators in commands and operands. */
static void test_axis_designators(void **state)
{
	struct tplant *p = *state;

	expect_reply(p, "~a=2;~b=\"B\";MG ~a,~b", ":: 2.0000 1.0000\r\n");
	expect_reply(p, "KP~a=7;MG _KP~a,_KPC", ": 7.0000 7.0000\r\n");
	expect_reply(p, "ZA~b=5;MG _ZAB", ": 5.0000\r\n");
	expect_error(p, "~a=9", 6);
	expect_reply(p, "~a=3", ""); /* no axis D: an error when used */
	expect_error(p, "SH~a", 6);
}

/* Listing, deallocation, formats and the small general commands. */
static void test_misc_commands(void **state)
{
	struct tplant *p = *state;
	char resp[256];

	expect_reply(p, "zeta=1;alpha=2.5;DM beta[3]", "::");
	expect_reply(p, "LV", "alpha = 2.5000\r\nzeta = 1.0000\r\n");
	expect_reply(p, "LA", "beta[3]\r\n");
	expect_reply(p, "MG _UL,_DM,_DA", " 508.0000 23997.0000 29.0000\r\n");
	expect_reply(p, "DA zeta;MG _UL", ": 509.0000\r\n");
	expect_error(p, "MG zeta", 1);
	expect_reply(p, "MG alpha", " 2.5000\r\n");
	expect_reply(p, "DA *,*[];MG _UL,_DA", ": 510.0000 30.0000\r\n");
	expect_reply(p, "DM ?", " 24000\r\n");
	expect_reply(p, "OP 5;MG _OP0,@OUT[1],@OUT[2],@OUT[3]",
		     ": 5.0000 1.0000 0.0000 1.0000\r\n");
	p->in.inputs = 0x0201;
	tp_step(p, 1);
	expect_reply(p, "TI 0;TI 1", " 1\r\n: 2\r\n");
	expect_reply(p, "MG _TI0,_TI1", " 1.0000 2.0000\r\n");
	expect_reply(p, "TA 0;MG _TA0", " 0\r\n: 0.0000\r\n");
	expect_reply(p, "MG _BV,_TM,_QZ1,_QZ3",
		     " 3.0000 1000.0000 52.0000 "
		     "36.0000\r\n");
	expect_reply(p, "VF 3.1;MG 2.25,-1234", ": 2.3 -999.9\r\n");
	expect_reply(p, "LZ 0;MG 2.25;x=7;x=?", ": 002.3\r\n:: 007.0\r\n");
	expect_reply(p, "VF 10.4;LZ 1;PF 5.2;DP 7;TP A", ":::: 7.00\r\n");
	expect_reply(p, "VF ?", "10.4\r\n");
	expect_error(p, "VF 11.0", 6);
	assert_int_equal(tp_cmd(p, "CW ?", resp, sizeof(resp)), GL_OK);
	assert_non_null(strstr(resp, "Copyright"));
	expect_error(p, "CW 3", 6);
	expect_error(p, "CF I", 6); /* the private port is not a handle */
	expect_error(p, "CF Q", 6);
	expect_reply(p, "CN 1;MG _CN0;CN -1", ": 1.0000\r\n:");
	expect_error(p, "CN 2", 6);
	expect_reply(p, "TB", " 0\r\n");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_left_to_right, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_fixed_point, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_functions, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_mg_formats, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_variables, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_arrays, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_dm_existing_array, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_da_forms, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_bad_commands, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_nested_if, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_if_without_endif, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_js_params, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_underscore_labels, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_js_depth, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_wt_timing, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_at_timing, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_threads, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_line_budget, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_cmderr, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_cmderr_thread0, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_error_stops_all, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_error_lines, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_trippoint_restore, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_zs, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_axis_designators, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_misc_commands, setup,
					    teardown),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
