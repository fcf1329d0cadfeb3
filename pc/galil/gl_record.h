/*
 * gl_record.h - the Galil QR/DR binary data record, decoded into a typed
 * struct.
 *
 * Layouts (little-endian, galil-notes.md section 2):
 *   DMC-40x0/41x3/500x0: QZ "n,52,26,36"  -> 82 + 36 bytes per axis
 *   DMC-30010:           QZ "1,18,16,36"  -> 74 bytes
 *   DMC-21x3:            QZ "n,24,16,28"  -> 44 + 28 bytes per axis
 * A record whose header or length disagrees with the layout is rejected whole.
 */
#ifndef GL_RECORD_H
#define GL_RECORD_H

#include <stddef.h>
#include <stdint.h>

#define GL_REC_MAX_AXES	 8
#define GL_REC_MAX_BYTES 370 /* 40x0 with 8 axes */

enum gl_rec_layout {
	GL_LAYOUT_NONE = 0,
	GL_LAYOUT_4000,	 /* DMC-40x0, 41x3, 500x0 */
	GL_LAYOUT_30000, /* DMC-30010 */
	GL_LAYOUT_2103,	 /* DMC-21x3 */
};

/* Axis status word bits (galil-notes.md 2.3). */
#define GL_AXST_MOVING	  (1u << 15)
#define GL_AXST_MODE_PAPR (1u << 14)
#define GL_AXST_MODE_PA	  (1u << 13)
#define GL_AXST_STOPPING  (1u << 4)
#define GL_AXST_MOTOR_OFF (1u << 0)

/* Axis switch byte bits; limit bits read 0 while the switch is active. */
#define GL_AXSW_FLS  (1u << 3) /* forward limit input state */
#define GL_AXSW_RLS  (1u << 2) /* reverse limit input state */
#define GL_AXSW_HOME (1u << 1)

struct gl_rec_axis {
	uint16_t status;   /* status word, GL_AXST_* */
	uint8_t switches;  /* GL_AXSW_* */
	uint8_t stop_code; /* _SCx */
	int32_t ref_pos;   /* _RPx, counts */
	int32_t motor_pos; /* _TPx, counts */
	int32_t pos_err;   /* _TEx, counts */
	int32_t aux_pos;   /* _TDx, counts */
	int32_t velocity;  /* 64 x _TVx, counts/s x 64 */
	int32_t torque;	   /* +-32767 = full scale */
	int32_t analog_in; /* ADC counts, the 16-bit field sign-extended
			    * (SW: AQ2 default); for UW settings
			    * (AQ3/AQ4) use (uint16_t)analog_in */
	uint8_t hall;	   /* _QHx (40x0 only) */
	int32_t za;	   /* user field ZAx (0 on 21x3) */
};

struct gl_record {
	enum gl_rec_layout layout;
	uint8_t header[4];	/* raw header bytes */
	uint16_t length;	/* bytes, including the 4 header bytes */
	uint16_t sample;	/* sample number (TIME, 16 bits) */
	uint8_t inputs[10];	/* input banks 0..9 (bank 0 = inputs 1..8) */
	uint8_t outputs[10];	/* output banks 0..9 */
	uint8_t handles[8];	/* Ethernet handle A..H status (40x0) */
	uint8_t error_code;	/* _TC */
	uint8_t threads;	/* bit n = thread n running (40x0, 30010) */
	uint8_t general_status; /* 21x3 only */
	uint32_t amp_status;	/* amplifier status (firmware dependent) */
	uint32_t contour_count;
	uint16_t contour_space;
	int n_axes;
	struct gl_rec_axis axis[GL_REC_MAX_AXES];
};

/*
 * gl_record_layout_from_qz() - pick the layout from a QZ reply.
 * @qz: the reply text, e.g. " 3, 52, 26, 36" (spaces and CR LF allowed).
 * @len: its length in bytes.
 * @layout: [out] the layout.
 * @n_axes: [out] the number of axes (1..8).
 * Return: GL_OK, GL_ERR_PROTO when the text is not 4 integers, or
 *         GL_ERR_RECORD when the sizes match no known layout.
 */
int gl_record_layout_from_qz(const char *qz, size_t len,
			     enum gl_rec_layout *layout, int *n_axes);

/*
 * gl_record_size() - expected record length in bytes for a layout.
 * Return: the length, or 0 for an unknown layout or axis count.
 */
size_t gl_record_size(enum gl_rec_layout layout, int n_axes);

/*
 * gl_record_decode() - decode one whole binary record (without the ':').
 * @buf: the bytes, starting with the 4-byte header.
 * @len: the number of bytes; must equal gl_record_size(layout, n_axes).
 * @layout, @n_axes: as found from QZ.
 * @out: [out] filled only on success; untouched on error.
 * Return: GL_OK; GL_ERR_RECORD when the header bit 7, the axis bits, the
 *         length field or @len disagree with the layout; GL_ERR_ARG on NULL.
 */
int gl_record_decode(const uint8_t *buf, size_t len, enum gl_rec_layout layout,
		     int n_axes, struct gl_record *out);

/*
 * gl_record_encode() - the inverse of gl_record_decode(), for the simulator
 * and the test stub. Header and length are computed from layout and n_axes.
 * @rec: the record; rec->layout and rec->n_axes are used.
 * @buf: [out] the bytes.
 * @cap: capacity of @buf.
 * Return: the number of bytes written (> 0), GL_ERR_OVERFLOW, or GL_ERR_ARG.
 */
int gl_record_encode(const struct gl_record *rec, uint8_t *buf, size_t cap);

#endif /* GL_RECORD_H */
