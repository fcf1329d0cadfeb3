/*
 * test_ctrl_fuzz.c - seeded random and mutated DMC programs and host input
 * for the simulated controller. Whatever comes in, the controller must not
 * crash (run under ASan/UBSan in `make asan`), must answer every command
 * line with ':' or '?', and must stay within its invariants (thread mask,
 * TC range, program limits). Bounded: a few thousand cases, seconds.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdlib.h>
#include <cmocka.h>

#include "test_ctrl_util.h"

#define CASES	   1500
#define HOST_LINES 5000

static uint64_t rng_state;

static uint32_t rnd(void)
{
	rng_state ^= rng_state << 13;
	rng_state ^= rng_state >> 7;
	rng_state ^= rng_state << 17;
	return (uint32_t)(rng_state >> 11);
}

static int pick(int n)
{
	return (int)(rnd() % (uint32_t)n);
}

static const char *const words[] = {
    "#A",
    "#B",
    "#LOOP",
    "#AUTO",
    "#CMDERR",
    "#POSERR",
    "#LIMSWI",
    "#AMPERR",
    "#TCPERR",
    "#MCTIME",
    "JP #A",
    "JP#LOOP,x<5",
    "JS #B",
    "JS #B(1,&x,3)",
    "JS #B(",
    "EN",
    "EN,,x",
    "EN1",
    "RE",
    "RE1",
    "RI",
    "ZS",
    "ZS1",
    "IF (x=1)",
    "IF(",
    "ELSE",
    "ENDIF",
    "WT 1",
    "WT 0",
    "WT -1",
    "AT 0",
    "AT -3",
    "AT 2,1",
    "AM",
    "MC",
    "MF 10",
    "MRB=-5",
    "AI 1",
    "AI -2",
    "XQ #B,1",
    "XQ #A,7",
    "XQ ,,1",
    "HX",
    "HX1",
    "HX9",
    "MG x",
    "MG \"hi\",x{F5.2}",
    "MG {EA}\"x\"",
    "MG {N}{^65}",
    "MG",
    "MG 1{Z",
    "x=x+1",
    "x=",
    "x=?",
    "y=(x*2)/3",
    "z=1/0",
    "x=$FF.8",
    "DM a[10]",
    "DM a[0]",
    "a[3]=4",
    "a[-1]=1",
    "a[99]=1",
    "DA a[]",
    "DA *",
    "^a=1",
    "^b",
    "~a=1",
    "~b=\"C\"",
    "~c=9",
    "SH",
    "SHA",
    "MO",
    "MOB",
    "BG",
    "BGA",
    "ST",
    "STC",
    "AB",
    "AB1",
    "PR 1000,,-500",
    "PRA=200",
    "PA 0",
    "PT 1",
    "PTA=0",
    "JG 1000",
    "JGB=-300",
    "SP 5000",
    "AC 1024",
    "DC*=2048",
    "KP 1,2,3",
    "KI ?",
    "ER 100",
    "OE 1,1,1",
    "OA 1",
    "OT 5",
    "OV 1",
    "TL 2",
    "FL 100",
    "BL -100",
    "DP 0",
    "ZAA=x",
    "CB 1",
    "SB 3",
    "OB 2,x",
    "TP",
    "TE",
    "SC",
    "TS",
    "TV",
    "TT",
    "RP",
    "TC1",
    "TC",
    "QR",
    "QZ",
    "TH",
    "WH",
    "CF A",
    "CF S",
    "CW 1",
    "CW ,1",
    "CW 2",
    "LV",
    "LA",
    "LL",
    "BN",
    "BV",
    "BP",
    "VF 5.2",
    "PF 8",
    "LZ 0",
    "TM 500",
    "IHT=>-3",
    "DL",
    "UL",
    "LS",
    "NO comment",
    "' quote",
    "REM rem",
    "_TPA",
    "bg",
    "XX",
    "@ABS[1]",
    "MG _XQ0,_HX1,_ED,_ED1,_TC,_NO,TIME,_TPA,_LFB,_ZAC,_TA0,_IA4",
    "x=@SIN[x]+@COM[x]&$FF|@RND[-x]%3",
    "MG (((((1)))))",
    "x=-(-(-1))",
};

static const char *const junk[] = {
    "(",    ")",  "[",	  "]",		"{",	       "}",	  "\"",
    "'",    ";",  ",",	  "=",		"<",	       ">",	  "<=",
    ">=",   "<>", "+",	  "-",		"*",	       "/",	  "%",
    "&",    "|",  "@",	  "_",		"^",	       "~",	  "#",
    "$",    "?",  " ",	  "9999999999", "-2147483648", "0.00001", "abcdefghij",
    "TIME", "\\", "\x1a", "\x12\x16",
};

static void add(char *line, size_t cap, const char *s)
{
	size_t n = strlen(line);

	snprintf(line + n, cap - n, "%s", s);
}

/* A random line: a few words and bits of junk joined by ';' or not. */
static void random_line(char *line, size_t cap)
{
	int i, n = 1 + pick(4);

	line[0] = '\0';
	for (i = 0; i < n; i++) {
		if (i)
			add(line, cap, pick(4) ? ";" : "");
		if (pick(5))
			add(line, cap,
			    words[pick(sizeof(words) / sizeof(words[0]))]);
		else
			add(line, cap,
			    junk[pick(sizeof(junk) / sizeof(junk[0]))]);
	}
	if (!pick(20)) { /* random bytes */
		size_t k = strlen(line), m = (size_t)pick(12);

		while (m-- && k + 1 < cap)
			line[k++] = (char)(1 + pick(255));
		line[k] = '\0';
	}
}

static size_t random_program(char *buf, size_t cap)
{
	char line[160];
	size_t n = 0;
	int i, lines = 1 + pick(40);

	n = (size_t)snprintf(buf, cap, "%s", pick(2) ? "#AUTO\r" : "");
	for (i = 0; i < lines && n + 170 < cap; i++) {
		random_line(line, sizeof(line));
		if (strlen(line) > 80 && pick(2))
			line[80] = '\0';
		n += (size_t)snprintf(buf + n, cap - n, "%s\r", line);
	}
	return n;
}

/* Flip, insert, delete a few bytes of a program. */
static void mutate(char *buf, size_t *len, size_t cap)
{
	int i, n = 1 + pick(6);
	size_t at;

	for (i = 0; i<n && * len> 0; i++) {
		at = (size_t)pick((int)*len);
		switch (pick(3)) {
		case 0: buf[at] = (char)pick(128); break;
		case 1:
			if (*len + 1 < cap) {
				memmove(buf + at + 1, buf + at, *len - at);
				buf[at] = "#;()[]\"{}=,\r"[pick(12)];
				(*len)++;
			}
			break;
		default:
			memmove(buf + at, buf + at + 1, *len - at - 1);
			(*len)--;
			break;
		}
	}
}

static void check_invariants(struct tplant *p)
{
	double tc = tp_mg(p, "_TC");
	unsigned th = ctrl_threads(p->c);
	struct ctrl_axis_info ai;
	int a;

	assert_true(tc >= 0 && tc < 256);
	assert_true(th < 256);
	for (a = 0; a < CTRL_AXES; a++) {
		assert_int_equal(ctrl_axis_info(p->c, a, &ai), GL_OK);
		assert_true(ai.stop_code >= 0 && ai.stop_code < 256);
	}
}

static void drain(struct tplant *p)
{
	uint8_t buf[4096];
	int h;

	for (h = 0; h < CTRL_HANDLES; h++)
		while (ctrl_output(p->c, h, buf, sizeof(buf)))
			;
	while (ctrl_serial_output(p->c, buf, sizeof(buf)))
		;
}

static const char base_prog[] =
    "EN\r#AUTO\rXQ #B,1;n=0\r#LOOP;n=n+1;IF (n>3);JS #S(n,2)\rELSE\r"
    "MG \"n\",n{Z3.0}\rENDIF;WT 2;JP #LOOP,n<20\rEN\r#B\rSH;PR 100,-50\r"
    "BG;AM;MO;EN\r#S\rEN,,^a*^b\r#CMDERR\re=_ED;EN\r#POSERR\rRE\r";

/* Random and mutated programs: download, start, run. */
static void test_fuzz_programs(void **state)
{
	static char prog[8192];
	struct tplant p;
	char resp[4096], line[64];
	size_t len;
	int i, k, bad;

	(void)state;
	rng_state = 0x9E3779B97F4A7C15ull;
	assert_int_equal(tp_init(&p), 0);
	for (i = 0; i < CASES; i++) {
		if (pick(2)) {
			len = random_program(prog, sizeof(prog));
		} else {
			len = sizeof(base_prog) - 1;
			memcpy(prog, base_prog, len);
			mutate(prog, &len, sizeof(prog));
		}
		tp_cmd(&p, "HX", resp, sizeof(resp));
		bad = 0;
		ctrl_download(p.c, prog, len, &bad);
		for (k = 0; k < 3; k++) {
			snprintf(line, sizeof(line), "XQ %s,%d",
				 (const char *[]){"#AUTO", "#LOOP", "0",
						  "#A"}[pick(4)],
				 pick(8));
			tp_cmd(&p, line, resp, sizeof(resp));
		}
		p.in.amp_power = pick(8) != 0;
		p.in.fwd_limit[pick(3)] = pick(2);
		p.in.inputs = rnd();
		p.frozen[pick(3)] = pick(2);
		tp_step(&p, 10 + pick(40));
		if (!pick(50))
			ctrl_power_cycle(p.c);
		drain(&p);
		check_invariants(&p);
	}
	tp_free(&p);
}

/* Random host bytes on random handles, including DL and control bytes. */
static void test_fuzz_host(void **state)
{
	struct tplant p;
	char line[200];
	uint8_t out[8192];
	size_t n;
	int i, h;
	double v;

	(void)state;
	rng_state = 0xD1B54A32D192ED03ull;
	assert_int_equal(tp_init(&p), 0);
	for (h = 0; h < CTRL_HANDLES; h++)
		ctrl_handle_open(p.c, h);
	for (i = 0; i < HOST_LINES; i++) {
		h = pick(CTRL_HANDLES);
		random_line(line, sizeof(line));
		if (!pick(10))
			add(line, sizeof(line), "\r#A;WT 1;JP #A\r\\");
		add(line, sizeof(line), "\r");
		tp_send(&p, h, line);
		ctrl_output(p.c, h, out, sizeof(out));
		if (!pick(4))
			tp_step(&p, 1 + pick(5));
		if (ctrl_handle_close_wanted(p.c, h) || !pick(200)) {
			ctrl_handle_close(p.c, h);
			ctrl_handle_open(p.c, h);
		}
		if (!pick(300))
			ctrl_handle_lost(p.c, pick(CTRL_HANDLES));
		ctrl_get_var(p.c, line, &v);
		if (!pick(10))
			ctrl_set_var(p.c, line, rnd());
		drain(&p);
		check_invariants(&p);
	}
	/* one plain command still works afterwards */
	tp_send(&p, 0, "\\\r\x1a\rHX;LZ 1;VF 10.4;MG 1+2*3\r");
	n = ctrl_output(p.c, 0, out, sizeof(out) - 1);
	out[n] = '\0';
	assert_non_null(strstr((char *)out, " 9.0000\r\n:"));
	tp_free(&p);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_fuzz_programs),
	    cmocka_unit_test(test_fuzz_host),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
