// Validates docs/openapi.yaml (OpenAPI 3.1) and prints its paths, one a line.
import SwaggerParser from '@apidevtools/swagger-parser';

try {
  const api = await SwaggerParser.validate(process.argv[2]);
  for (const path of Object.keys(api.paths)) console.log(path);
} catch (e) {
  console.error(`invalid: ${e.message}`);
  process.exit(1);
}
