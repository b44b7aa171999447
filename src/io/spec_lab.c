// Lab files (docs/lab.md): the sample, the material model and the traction
// settings of `plume lab traction`. Keys are the fields of plume_sample_def,
// plume_lab_material and plume_traction_def; angles are in degrees.
#include <string.h>

#include "plume/lab.h"
#include "spec.h"

static const double PI = 3.14159265358979323846;

static const char *const top_keys[] = {"sample", "material", "traction", "description", NULL};
static const char *const sample_keys[] = {"width", "height",   "thickness", "barb_angle_deg",
                                          "mesh",  "elements", "seed",      NULL};
static const char *const material_keys[] = {
    "model",      "E_vv",          "E_ww",        "E_vw",           "barb_constraint",   "E_B",
    "E_b",        "barb_fraction", "band_period", "barb_divisions", "barbule_divisions", "compression_coefficient",
    "band_phase", "elements",      NULL};
static const char *const traction_keys[] = {
    "strain_max",      "steps",       "tolerance", "max_iterations", "max_substep_halvings", "require_convergence",
    "accept_residual", "compression", NULL};

static void read_sample(plume_spec_reader *reader, const json_t *object, plume_sample_def *sample)
{
	if (object == NULL)
		return;
	plume_spec_check_keys(reader, object, "$.sample", sample_keys);
	plume_spec_number(reader, object, "$.sample", "width", &sample->width);
	plume_spec_number(reader, object, "$.sample", "height", &sample->height);
	plume_spec_number(reader, object, "$.sample", "thickness", &sample->thickness);
	double angle_deg = sample->barb_angle * 180.0 / PI;
	if (plume_spec_number(reader, object, "$.sample", "barb_angle_deg", &angle_deg))
		sample->barb_angle = angle_deg * PI / 180.0;
	const char *mesh = NULL;
	if (plume_spec_string(reader, object, "$.sample", "mesh", &mesh)) {
		if (strcmp(mesh, "aligned") == 0)
			sample->mesh = PLUME_SAMPLE_ALIGNED;
		else if (strcmp(mesh, "unaligned") == 0)
			sample->mesh = PLUME_SAMPLE_UNALIGNED;
		else
			plume_spec_fail(reader, "$.sample.mesh", "is \"%s\", allowed \"aligned\" or \"unaligned\"", mesh);
	}
	plume_spec_int(reader, object, "$.sample", "elements", &sample->element_count);
	plume_spec_uint64(reader, object, "$.sample", "seed", &sample->seed);
}

static void read_material(plume_spec_reader *reader, const json_t *object, plume_lab_material *material)
{
	if (object == NULL)
		return;
	plume_spec_check_keys(reader, object, "$.material", material_keys);
	const char *model = NULL;
	if (plume_spec_string(reader, object, "$.material", "model", &model)) {
		if (strcmp(model, "macroscale") == 0)
			material->model = PLUME_LAB_MACROSCALE;
		else if (strcmp(model, "mesoscale") == 0)
			material->model = PLUME_LAB_MESOSCALE;
		else
			plume_spec_fail(reader, "$.material.model", "is \"%s\", allowed \"macroscale\" or \"mesoscale\"", model);
	}
	plume_spec_number(reader, object, "$.material", "E_vv", &material->E_vv);
	plume_spec_number(reader, object, "$.material", "E_ww", &material->E_ww);
	plume_spec_number(reader, object, "$.material", "E_vw", &material->E_vw);
	plume_spec_bool(reader, object, "$.material", "barb_constraint", &material->barb_constraint);
	plume_spec_number(reader, object, "$.material", "E_B", &material->E_B);
	plume_spec_number(reader, object, "$.material", "E_b", &material->E_b);
	plume_spec_number(reader, object, "$.material", "barb_fraction", &material->bands.barb_fraction);
	plume_spec_number(reader, object, "$.material", "band_period", &material->bands.period);
	plume_spec_number(reader, object, "$.material", "band_phase", &material->bands.phase);
	plume_spec_int(reader, object, "$.material", "barb_divisions", &material->bands.barb_divisions);
	plume_spec_int(reader, object, "$.material", "barbule_divisions", &material->bands.barbule_divisions);
	plume_spec_number(reader, object, "$.material", "compression_coefficient", &material->compression_coefficient);
	const char *elements = NULL;
	if (plume_spec_string(reader, object, "$.material", "elements", &elements)) {
		if (strcmp(elements, "linear") == 0 || strcmp(elements, "quadratic") == 0)
			material->quadratic = strcmp(elements, "quadratic") == 0;
		else
			plume_spec_fail(reader, "$.material.elements", "is \"%s\", allowed \"linear\" or \"quadratic\"", elements);
	}
}

static void read_traction(plume_spec_reader *reader, const json_t *object, plume_traction_def *traction)
{
	if (object == NULL)
		return;
	plume_spec_check_keys(reader, object, "$.traction", traction_keys);
	plume_spec_number(reader, object, "$.traction", "strain_max", &traction->strain_max);
	plume_spec_int(reader, object, "$.traction", "steps", &traction->steps);
	plume_spec_number(reader, object, "$.traction", "tolerance", &traction->solver.tolerance);
	plume_spec_int(reader, object, "$.traction", "max_iterations", &traction->solver.max_iterations);
	plume_spec_int(reader, object, "$.traction", "max_substep_halvings", &traction->solver.max_substep_halvings);
	plume_spec_bool(reader, object, "$.traction", "require_convergence", &traction->require_convergence);
	plume_spec_number(reader, object, "$.traction", "accept_residual", &traction->accept_residual);
	plume_spec_bool(reader, object, "$.traction", "compression", &traction->compression);
}

plume_status plume_lab_spec_load(const char *path, plume_lab_spec *spec, plume_error *err)
{
	json_t *root = plume_spec_load(path, err);
	if (root == NULL)
		return err != NULL ? err->status : PLUME_ERROR_IO;
	plume_lab_spec result;
	result.sample = plume_sample_default_def();
	result.traction = plume_traction_default_def();
	plume_spec_reader reader = plume_spec_reader_begin(path, err);
	if (!json_is_object(root))
		plume_spec_fail(&reader, "$", "expected an object with \"sample\", \"material\" and \"traction\"");
	plume_spec_check_keys(&reader, root, "$", top_keys);
	const json_t *material = plume_spec_object(&reader, root, "$", "material");
	// The model decides the defaults of the other material keys.
	const char *model = NULL;
	result.material = plume_lab_material_default(PLUME_LAB_MACROSCALE);
	if (material != NULL && plume_spec_string(&reader, material, "$.material", "model", &model) &&
	    strcmp(model, "mesoscale") == 0)
		result.material = plume_lab_material_default(PLUME_LAB_MESOSCALE);
	read_sample(&reader, plume_spec_object(&reader, root, "$", "sample"), &result.sample);
	read_material(&reader, material, &result.material);
	read_traction(&reader, plume_spec_object(&reader, root, "$", "traction"), &result.traction);
	const char *description;
	plume_spec_string(&reader, root, "$", "description", &description);
	plume_status status = reader.status;
	json_decref(root);
	if (status != PLUME_OK)
		return status;
	// Value checks: the messages name the field as "sample.width ..."; make them "file: $.sample.width ...".
	plume_error check = {0};
	status = plume_lab_validate(&result.material, &result.sample, &result.traction, &check);
	if (status == PLUME_OK)
		status = plume_sample_validate(
		    &result.sample, result.material.model == PLUME_LAB_MESOSCALE ? &result.material.bands : NULL, &check);
	if (status != PLUME_OK) {
		plume_error_set(err, status, "%s: $.%s", path, check.message);
		return status;
	}
	*spec = result;
	return PLUME_OK;
}
