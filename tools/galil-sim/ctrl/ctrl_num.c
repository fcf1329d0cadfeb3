/*
 * ctrl_num.c - Galil numbers: 32 bits of integer and 16 bits of fraction
 * (+-2147483647.9999, resolution 1/65536), and the printed formats.
 *
 * Values travel as doubles, which hold every 48-bit fixed-point value
 * exactly; ctrl_fx() brings the result of each operation back onto the
 * 1/65536 grid (rounding to nearest) and wraps it like a 48-bit two's
 * complement register (UNCONFIRMED: the firmware's overflow behaviour).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ctrl_num.h"

#define FX_BITS 48
#define FX_MOD	281474976710656.0 /* 2^48 */

int64_t ctrl_fx_raw(double v)
{
	double r;
	int64_t raw;

	if (isnan(v))
		return 0;
	r = v * CTRL_FX_ONE;
	if (!(fabs(r) < 9.0e18)) /* inf or far out of range */
		r = isinf(r) ? (r > 0 ? FX_MOD / 2 - 1 : -FX_MOD / 2)
			     : fmod(r, FX_MOD);
	raw = (int64_t)llround(r);
	/* wrap into the signed 48-bit range */
	raw &= (((int64_t)1 << FX_BITS) - 1);
	if (raw & ((int64_t)1 << (FX_BITS - 1)))
		raw -= ((int64_t)1 << FX_BITS);
	return raw;
}

double ctrl_fx_from_raw(int64_t raw)
{
	return (double)raw / CTRL_FX_ONE;
}

double ctrl_fx(double v)
{
	return ctrl_fx_from_raw(ctrl_fx_raw(v));
}

/* Pack up to 6 characters, first character in the most significant byte. */
double ctrl_str_value(const char *s, size_t n)
{
	int64_t raw = 0;
	size_t i;

	for (i = 0; i < 6; i++) {
		raw <<= 8;
		if (i < n)
			raw |= (uint8_t)s[i];
	}
	if (raw & ((int64_t)1 << (FX_BITS - 1)))
		raw -= ((int64_t)1 << FX_BITS);
	return ctrl_fx_from_raw(raw);
}

static const int64_t pow10_tab[] = {
    1,	     10,       100,	  1000,	      10000,	     100000,
    1000000, 10000000, 100000000, 1000000000, 10000000000LL,
};

/* Decimal F/Z format: sign (space or '-'), integer, '.', n decimals. */
static int fmt_dec(char *out, size_t cap, double v, const struct ctrl_fmt *f)
{
	int64_t raw = ctrl_fx_raw(v), mag, ip, fp, scaled, maxv;
	int m = f->m, n = f->n, neg = raw < 0;
	char digits[32];

	if (m < 0 || m > 10 || n < 0 || n > 4)
		return -1;
	mag = neg ? -raw : raw;
	ip = mag >> 16;
	fp = mag & 0xFFFF;
	scaled = ip * pow10_tab[n] + (fp * pow10_tab[n] + 32768) / 65536;
	maxv = pow10_tab[m] * pow10_tab[n] - 1; /* "999.99" when too big */
	if (scaled > maxv)
		scaled = maxv;
	if (scaled == 0)
		neg = 0;
	ip = scaled / pow10_tab[n];
	fp = scaled % pow10_tab[n];
	if (f->kind == 'F' && m > 0)
		snprintf(digits, sizeof(digits), "%0*lld", m, (long long)ip);
	else
		snprintf(digits, sizeof(digits), "%lld", (long long)ip);
	if (n > 0)
		return snprintf(out, cap, "%c%s.%0*lld", neg ? '-' : ' ',
				digits, n, (long long)fp);
	return snprintf(out, cap, "%c%s", neg ? '-' : ' ', digits);
}

/*
 * Hex: '$', m hex digits of the integer part, '.', n of the fraction. A
 * negative value shows the low m digits of its two's complement (command
 * reference TP: PF-6.0 prints -10 as $FFFFF6); a positive one too big for
 * m digits saturates to all F, as {Fm.n} saturates to all 9
 * (UNCONFIRMED: the reference shows no overflow).
 */
static int fmt_hex(char *out, size_t cap, double v, const struct ctrl_fmt *f)
{
	uint64_t u = (uint64_t)ctrl_fx_raw(v) & (((uint64_t)1 << 48) - 1);
	uint32_t ip = (uint32_t)(u >> 16);
	unsigned fp = (unsigned)(u & 0xFFFF);
	int m = f->m, n = f->n;
	char ib[16], fb[8];

	if (m < 1 || m > 8 || n < 0 || n > 4)
		return -1;
	if (!(u >> 47) && m < 8 && ip >> (4 * m)) {
		/* too big for m digits: saturate as {Fm.n} does ("$FF") */
		ip = (1u << (4 * m)) - 1;
		fp = 0xFFFF;
	}
	snprintf(ib, sizeof(ib), "%08X", (unsigned)ip);
	snprintf(fb, sizeof(fb), "%04X", fp);
	if (n > 0)
		return snprintf(out, cap, "$%s.%.*s", ib + 8 - m, n, fb);
	return snprintf(out, cap, "$%s", ib + 8 - m);
}

/* String: the characters packed into the value, NULs left out. */
static int fmt_str(char *out, size_t cap, double v, const struct ctrl_fmt *f)
{
	uint64_t u = (uint64_t)ctrl_fx_raw(v);
	size_t k = 0;
	int i;

	if (f->m < 1 || f->m > 6 || cap < 8)
		return -1;
	for (i = 0; i < f->m; i++) {
		char ch = (char)((u >> (40 - 8 * i)) & 0xFF);

		if (ch)
			out[k++] = ch;
	}
	out[k] = '\0';
	return (int)k;
}

/*
 * ctrl_fmt_num() - print @v in format @f into @out.
 * Return: characters written (snprintf style), or -1 for a bad format.
 */
int ctrl_fmt_num(char *out, size_t cap, double v, const struct ctrl_fmt *f)
{
	switch (f->kind) {
	case 'F':
	case 'Z': return fmt_dec(out, cap, v, f);
	case '$': return fmt_hex(out, cap, v, f);
	case 'S': return fmt_str(out, cap, v, f);
	default: return -1;
	}
}
