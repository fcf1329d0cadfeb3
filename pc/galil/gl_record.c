/*
 * gl_record.c - decode and encode the Galil QR/DR binary data record.
 *
 * Layouts and offsets: galil-notes.md section 2 (gclib GDataRecord4000,
 * GDataRecord30000, GDataRecord2103). Every multi-byte field is
 * little-endian. Decoding is all-or-nothing: the header, the length field
 * and the buffer length are checked against the layout first, and the
 * caller's struct is written only when the whole record is valid.
 *
 * Header byte 0: bit 7 always set, bit 2 I/O block, bit 1 T plane, bit 0
 * S plane. A full QR (no argument) on the 40x0 and the 21x3 carries all
 * three (0x87). The DMC-30010 has no T plane in its record (QZ says 16
 * coordinated bytes = contour + S plane); whether its header sets bit 1 is
 * UNCONFIRMED, so both 0x85 and 0x87 are accepted there and 0x85 is sent.
 */
#include <string.h>

#include "gl_err.h"
#include "gl_record.h"

#define HDR_BIT7 0x80u
#define HDR_IO	 0x04u
#define HDR_T	 0x02u
#define HDR_S	 0x01u
#define HDR_FULL (HDR_BIT7 | HDR_IO | HDR_T | HDR_S)

/* Per-layout geometry. */
#define R4000_GENERAL  82 /* header + general + S/T planes */
#define R4000_AXIS     36
#define R30000_GENERAL 38
#define R30000_SIZE    74
#define R2103_GENERAL  44
#define R2103_AXIS     28

/* QZ fields: general bytes, coordinated bytes, axis bytes. */
#define QZ4000_GEN    52
#define QZ4000_COORD  26
#define QZ4000_AXIS   36
#define QZ30000_GEN   18
#define QZ30000_COORD 16
#define QZ2103_GEN    24
#define QZ2103_COORD  16
#define QZ2103_AXIS   28

/* ---- little-endian helpers ----------------------------------------------- */

static uint16_t get_u16(const uint8_t *p)
{
	return (uint16_t)(p[0] | (p[1] << 8));
}

static uint32_t get_u32(const uint8_t *p)
{
	return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
	       ((uint32_t)p[3] << 24);
}

static int32_t get_s32(const uint8_t *p)
{
	uint32_t u = get_u32(p);

	/* two's complement without implementation-defined conversion */
	if (u & 0x80000000u)
		return (int32_t)(u - 0x80000000u) - INT32_MAX - 1;
	return (int32_t)u;
}

static int16_t get_s16(const uint8_t *p)
{
	uint16_t u = get_u16(p);

	if (u & 0x8000u)
		return (int16_t)((int)u - 0x10000);
	return (int16_t)u;
}

static void put_u16(uint8_t *p, uint32_t v)
{
	p[0] = (uint8_t)(v & 0xff);
	p[1] = (uint8_t)((v >> 8) & 0xff);
}

static void put_u32(uint8_t *p, uint32_t v)
{
	put_u16(p, v & 0xffff);
	put_u16(p + 2, v >> 16);
}

static void put_s32(uint8_t *p, int32_t v)
{
	put_u32(p, (uint32_t)v);
}

/* ---- layout selection ---------------------------------------------------- */

size_t gl_record_size(enum gl_rec_layout layout, int n_axes)
{
	if (n_axes < 1 || n_axes > GL_REC_MAX_AXES)
		return 0;
	switch (layout) {
	case GL_LAYOUT_4000: return R4000_GENERAL + R4000_AXIS * (size_t)n_axes;
	case GL_LAYOUT_30000: return n_axes == 1 ? R30000_SIZE : 0;
	case GL_LAYOUT_2103: return R2103_GENERAL + R2103_AXIS * (size_t)n_axes;
	case GL_LAYOUT_NONE: break;
	}
	return 0;
}

/* Parse up to 4 comma-separated non-negative integers; whitespace allowed. */
static int parse_qz(const char *s, size_t len, long v[4])
{
	size_t i = 0;
	int n = 0;

	while (n < 4) {
		long x = 0;
		int digits = 0;

		while (i < len && (s[i] == ' ' || s[i] == '\t'))
			i++;
		while (i < len && s[i] >= '0' && s[i] <= '9' && digits < 6) {
			x = x * 10 + (s[i++] - '0');
			digits++;
		}
		if (digits == 0 || (i < len && s[i] >= '0' && s[i] <= '9'))
			return GL_ERR_PROTO;
		v[n++] = x;
		while (i < len && (s[i] == ' ' || s[i] == '\t'))
			i++;
		if (n < 4 && (i >= len || s[i++] != ','))
			return GL_ERR_PROTO;
	}
	while (i < len &&
	       (s[i] == ' ' || s[i] == '\t' || s[i] == '\r' || s[i] == '\n'))
		i++;
	return i == len ? GL_OK : GL_ERR_PROTO;
}

int gl_record_layout_from_qz(const char *qz, size_t len,
			     enum gl_rec_layout *layout, int *n_axes)
{
	long v[4];
	enum gl_rec_layout lay = GL_LAYOUT_NONE;

	if (!qz || !layout || !n_axes)
		return GL_ERR_ARG;
	if (parse_qz(qz, len, v) < 0)
		return GL_ERR_PROTO;
	if (v[1] == QZ4000_GEN && v[2] == QZ4000_COORD && v[3] == QZ4000_AXIS)
		lay = GL_LAYOUT_4000;
	else if (v[1] == QZ30000_GEN && v[2] == QZ30000_COORD &&
		 v[3] == QZ4000_AXIS)
		lay = GL_LAYOUT_30000;
	else if (v[1] == QZ2103_GEN && v[2] == QZ2103_COORD &&
		 v[3] == QZ2103_AXIS)
		lay = GL_LAYOUT_2103;
	if (lay == GL_LAYOUT_NONE || gl_record_size(lay, (int)v[0]) == 0)
		return GL_ERR_RECORD;
	*layout = lay;
	*n_axes = (int)v[0];
	return GL_OK;
}

/* ---- header -------------------------------------------------------------- */

static uint8_t header_byte0(enum gl_rec_layout layout)
{
	return layout == GL_LAYOUT_30000 ? (HDR_BIT7 | HDR_IO | HDR_S)
					 : HDR_FULL;
}

static int header_ok(const uint8_t *buf, size_t size, enum gl_rec_layout layout,
		     int n_axes)
{
	uint8_t axes = (uint8_t)((1u << n_axes) - 1u);

	if (buf[0] != header_byte0(layout) &&
	    !(layout == GL_LAYOUT_30000 && buf[0] == HDR_FULL))
		return 0;
	if (buf[1] != axes)
		return 0;
	return get_u16(buf + 2) == size;
}

/* ---- axis blocks --------------------------------------------------------- */

/* The common first 24 bytes of an axis block (all layouts). */
static void axis_decode_common(const uint8_t *p, struct gl_rec_axis *a)
{
	a->status = get_u16(p);
	a->switches = p[2];
	a->stop_code = p[3];
	a->ref_pos = get_s32(p + 4);
	a->motor_pos = get_s32(p + 8);
	a->pos_err = get_s32(p + 12);
	a->aux_pos = get_s32(p + 16);
	a->velocity = get_s32(p + 20);
}

static void axis_encode_common(uint8_t *p, const struct gl_rec_axis *a)
{
	put_u16(p, a->status);
	p[2] = a->switches;
	p[3] = a->stop_code;
	put_s32(p + 4, a->ref_pos);
	put_s32(p + 8, a->motor_pos);
	put_s32(p + 12, a->pos_err);
	put_s32(p + 16, a->aux_pos);
	put_s32(p + 20, a->velocity);
}

/* 36-byte block of the 40x0 and 30010 records. */
static void axis_decode36(const uint8_t *p, struct gl_rec_axis *a)
{
	axis_decode_common(p, a);
	a->torque = get_s32(p + 24);
	a->analog_in = get_s16(p + 28);
	a->hall = p[30];
	a->za = get_s32(p + 32);
}

static void axis_encode36(uint8_t *p, const struct gl_rec_axis *a)
{
	axis_encode_common(p, a);
	put_s32(p + 24, a->torque);
	put_u16(p + 28, (uint32_t)a->analog_in & 0xffffu);
	p[30] = a->hall;
	p[31] = 0;
	put_s32(p + 32, a->za);
}

/* 28-byte block of the 21x3 record: torque is SW, no hall, no ZA. */
static void axis_decode28(const uint8_t *p, struct gl_rec_axis *a)
{
	axis_decode_common(p, a);
	a->torque = get_s16(p + 24);
	a->analog_in = get_s16(p + 26);
	a->hall = 0;
	a->za = 0;
}

static void axis_encode28(uint8_t *p, const struct gl_rec_axis *a)
{
	axis_encode_common(p, a);
	put_u16(p + 24, (uint32_t)a->torque & 0xffffu);
	put_u16(p + 26, (uint32_t)a->analog_in & 0xffffu);
}

/* ---- general blocks ------------------------------------------------------ */

static void general_decode_4000(const uint8_t *b, struct gl_record *r)
{
	memcpy(r->inputs, b + 6, 10);
	memcpy(r->outputs, b + 16, 10);
	memcpy(r->handles, b + 42, 8);
	r->error_code = b[50];
	r->threads = b[51];
	r->amp_status = get_u32(b + 52);
	r->contour_count = get_u32(b + 56);
	r->contour_space = get_u16(b + 60);
}

static void general_encode_4000(uint8_t *b, const struct gl_record *r)
{
	memcpy(b + 6, r->inputs, 10);
	memcpy(b + 16, r->outputs, 10);
	memcpy(b + 42, r->handles, 8);
	b[50] = r->error_code;
	b[51] = r->threads;
	put_u32(b + 52, r->amp_status);
	put_u32(b + 56, r->contour_count);
	put_u16(b + 60, r->contour_space);
}

static void general_decode_30000(const uint8_t *b, struct gl_record *r)
{
	r->inputs[0] = b[6];
	r->inputs[1] = b[7];
	r->outputs[0] = b[8];
	r->outputs[1] = b[9];
	r->error_code = b[10];
	r->threads = b[11];
	r->amp_status = get_u32(b + 18);
	r->contour_count = get_u32(b + 22);
	r->contour_space = get_u16(b + 26);
}

static void general_encode_30000(uint8_t *b, const struct gl_record *r)
{
	b[6] = r->inputs[0];
	b[7] = r->inputs[1];
	b[8] = r->outputs[0];
	b[9] = r->outputs[1];
	b[10] = r->error_code;
	b[11] = r->threads;
	put_u32(b + 18, r->amp_status);
	put_u32(b + 22, r->contour_count);
	put_u16(b + 26, r->contour_space);
}

static void general_decode_2103(const uint8_t *b, struct gl_record *r)
{
	memcpy(r->inputs, b + 6, 10);
	memcpy(r->outputs, b + 16, 10);
	r->error_code = b[26];
	r->general_status = b[27];
}

static void general_encode_2103(uint8_t *b, const struct gl_record *r)
{
	memcpy(b + 6, r->inputs, 10);
	memcpy(b + 16, r->outputs, 10);
	b[26] = r->error_code;
	b[27] = r->general_status;
}

/* ---- public -------------------------------------------------------------- */

static void decode_body(const uint8_t *buf, enum gl_rec_layout layout,
			int n_axes, struct gl_record *r)
{
	int i;

	memset(r, 0, sizeof(*r));
	r->layout = layout;
	r->n_axes = n_axes;
	memcpy(r->header, buf, 4);
	r->length = get_u16(buf + 2);
	r->sample = get_u16(buf + 4);
	if (layout == GL_LAYOUT_4000) {
		general_decode_4000(buf, r);
		for (i = 0; i < n_axes; i++)
			axis_decode36(buf + R4000_GENERAL + R4000_AXIS * i,
				      &r->axis[i]);
	} else if (layout == GL_LAYOUT_30000) {
		general_decode_30000(buf, r);
		axis_decode36(buf + R30000_GENERAL, &r->axis[0]);
	} else {
		general_decode_2103(buf, r);
		for (i = 0; i < n_axes; i++)
			axis_decode28(buf + R2103_GENERAL + R2103_AXIS * i,
				      &r->axis[i]);
	}
}

int gl_record_decode(const uint8_t *buf, size_t len, enum gl_rec_layout layout,
		     int n_axes, struct gl_record *out)
{
	size_t size;

	if (!buf || !out)
		return GL_ERR_ARG;
	size = gl_record_size(layout, n_axes);
	if (size == 0 || len != size || !header_ok(buf, size, layout, n_axes))
		return GL_ERR_RECORD;
	decode_body(buf, layout, n_axes, out);
	return GL_OK;
}

int gl_record_encode(const struct gl_record *rec, uint8_t *buf, size_t cap)
{
	size_t size;
	int i;

	if (!rec || !buf)
		return GL_ERR_ARG;
	size = gl_record_size(rec->layout, rec->n_axes);
	if (size == 0)
		return GL_ERR_ARG;
	if (cap < size)
		return GL_ERR_OVERFLOW;
	memset(buf, 0, size);
	buf[0] = header_byte0(rec->layout);
	buf[1] = (uint8_t)((1u << rec->n_axes) - 1u);
	put_u16(buf + 2, (uint32_t)size);
	put_u16(buf + 4, rec->sample);
	if (rec->layout == GL_LAYOUT_4000) {
		general_encode_4000(buf, rec);
		for (i = 0; i < rec->n_axes; i++)
			axis_encode36(buf + R4000_GENERAL + R4000_AXIS * i,
				      &rec->axis[i]);
	} else if (rec->layout == GL_LAYOUT_30000) {
		general_encode_30000(buf, rec);
		axis_encode36(buf + R30000_GENERAL, &rec->axis[0]);
	} else {
		general_encode_2103(buf, rec);
		for (i = 0; i < rec->n_axes; i++)
			axis_encode28(buf + R2103_GENERAL + R2103_AXIS * i,
				      &rec->axis[i]);
	}
	return (int)size;
}
