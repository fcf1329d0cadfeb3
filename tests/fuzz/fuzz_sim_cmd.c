/*
 * fuzz_sim_cmd.c - libFuzzer target: galil-sim's host command interpreter
 * (ctrl_input() on the Ethernet handles: framing, command parser,
 * expressions, DL/UL, QR, IH, and the program threads a command starts).
 *
 * Input: [0] chunk size - 1, [1] bit 0-2: the second handle used, bit 3:
 * power cycle at the end; then the bytes the hosts send, alternately on
 * handle A and on the second handle, one chunk at a time. Between chunks
 * the controller runs a few servo samples (a trivial plant: the encoders
 * follow the reference) and every output queue is drained. A fresh
 * controller per input: no state survives between inputs.
 */
#include <stdint.h>
#include <stddef.h>
#include <string.h>
#include <stdlib.h>
#include "ctrl.h"
#include "gl_err.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define SAMPLES_PER_CHUNK 4
#define MAX_SAMPLES	  400

static void step(struct ctrl *c, struct ctrl_sense *in, int n)
{
	struct ctrl_drive out;
	int i, a;

	for (i = 0; i < n; i++) {
		ctrl_step(c, in, &out);
		for (a = 0; a < CTRL_AXES; a++)
			if (out.motor_on[a])
				in->enc[a] = out.ref[a];
	}
}

static void drain(struct ctrl *c)
{
	uint8_t buf[512];
	int h;

	for (h = 0; h < CTRL_HANDLES; h++) {
		while (ctrl_output(c, h, buf, sizeof(buf)))
			;
		if (ctrl_handle_close_wanted(c, h)) {
			ctrl_handle_close(c, h);
			ctrl_handle_open(c, h);
		}
	}
	while (ctrl_serial_output(c, buf, sizeof(buf)))
		;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ctrl_cfg cfg;
	struct ctrl_sense in;
	struct ctrl *c;
	size_t pos = 2, chunk;
	int h2, turn = 0, samples = 0;

	if (size < 2)
		return 0;
	memset(&cfg, 0, sizeof(cfg));
	cfg.model = "DMC4030 Rev 1.2h-sim";
	cfg.serial = 4242;
	cfg.sample_us = 1000;
	c = ctrl_new(&cfg);
	if (!c)
		return 0;
	memset(&in, 0, sizeof(in));
	in.amp_power = 1;
	chunk = (size_t)data[0] + 1;
	h2 = data[1] & 7;
	ctrl_handle_open(c, 0);
	if (h2)
		ctrl_handle_open(c, h2);
	while (pos < size) {
		size_t n = size - pos < chunk ? size - pos : chunk;

		if (ctrl_input(c, turn ? h2 : 0, data + pos, n) != 0)
			abort(); /* handles 0..7 are valid */
		pos += n;
		turn = !turn;
		if (samples < MAX_SAMPLES) {
			step(c, &in, SAMPLES_PER_CHUNK);
			samples += SAMPLES_PER_CHUNK;
		}
		drain(c);
	}
	if (data[1] & 8) {
		ctrl_power_cycle(c);
		step(c, &in, SAMPLES_PER_CHUNK);
		drain(c);
	}
	ctrl_free(c);
	return 0;
}
