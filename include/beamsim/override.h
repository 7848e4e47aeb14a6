/* An override of a scene field (scene.h, experiment.h): what `--set` and an
 * experiment's set: and grid: give. */
#ifndef BSIM_OVERRIDE_H
#define BSIM_OVERRIDE_H

/* One override of a scene field by dotted path, e.g. key "beams.0.stiffness",
 * value "250" (any YAML flow text: "7", "[0, 5]", "{force: 7}"). origin names
 * where it came from for error messages: "--set" or "h2.yaml:14". */
typedef struct bsim_override {
	const char *key;
	const char *value;
	const char *origin;
} bsim_override;

#endif
