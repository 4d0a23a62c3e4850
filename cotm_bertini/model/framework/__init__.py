"""Compliant tensegrity frameworks described in a file: the general model beside the paper's."""
