"""Field locations of the Python client (client/python/mbopt/locator.py):
the line and column of each field in a text-format study, which name the
fields of the server's messages as `mbopt validate` names them. No server:
the text is parsed here (the e2e test, python_client_test.py, compares whole
messages with the CLI's)."""

import unittest

from google.protobuf import text_format

from mbopt.locator import FieldLocations
from mbopt.v1 import study_pb2

# Tokens that a naive scanner splits or misreads: exponents with a sign,
# negative numbers, infinity, comments holding quotes and braces, adjacent
# strings, a list of messages, angle brackets.
STUDY = '''# a comment with "quotes" and { a brace
name: "t"  # trailing }
variables { name: "x1" parameter: "k1" scale: 1e-3 initial: -2.5E+1 lower: -inf upper: 3 also_sets: ["a", "b"] }
variables <
  name: "x2"
  upper: 1
>
constraints: [ { name: "c1" limit: 1 }, { name: "c2" limit: 2.5e+2 } ]
description: "a" 'b'
objective { minimize_max_of: "y" }
'''


class FieldLocationsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.locations = FieldLocations(STUDY, study_pb2.Study.DESCRIPTOR)

    def test_text_is_a_valid_study(self):
        study = text_format.Parse(STUDY, study_pb2.Study())
        self.assertEqual((study.variables[0].scale, study.constraints[1].limit), (1e-3, 250))

    def test_fields_after_signed_exponents_and_infinity(self):
        self.assertEqual(self.locations.find("variables[0].upper"), (3, 81))
        self.assertEqual(self.locations.find("variables[0].also_sets"), (3, 90))

    def test_repeated_field_in_angle_brackets(self):
        self.assertEqual(self.locations.find("variables[1]"), (4, 1))
        self.assertEqual(self.locations.find("variables[1].upper"), (6, 3))

    def test_repeated_field_without_index_is_its_first_element(self):
        self.assertEqual(self.locations.find("variables"), (3, 1))

    def test_elements_of_a_list_of_messages(self):
        # One location for the list, the name's, as protoc's parser records it.
        self.assertEqual(self.locations.find("constraints[0]"), (8, 1))
        self.assertIsNone(self.locations.find("constraints[1]"))
        self.assertEqual(self.locations.find("constraints[1].limit"), (8, 54))

    def test_field_after_adjacent_strings(self):
        self.assertEqual(self.locations.find("objective.minimize_max_of"), (10, 13))

    def test_unset_field_is_where_the_message_holding_it_is(self):
        self.assertEqual(self.locations.find("objective.reduction"), (10, 1))
        self.assertEqual(self.locations.find("variables[1].lower"), (4, 1))

    def test_unset_top_level_field_has_no_line(self):
        self.assertIsNone(self.locations.find("cases[0].name"))

    def test_token_after_a_name(self):
        self.assertEqual(self.locations.token_after(2, 1), (2, 5))


if __name__ == "__main__":
    unittest.main()
